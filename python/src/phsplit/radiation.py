"""Cummins' fluid memory from a Capytaine dataset, as a linear port-Hamiltonian subsystem
(``[port_hamiltonian]``, docs/explanation/components/port-hamiltonian.md): the method and its
sources are on docs/explanation/components/fluid-memory.md.

Cummins' equation (W. E. Cummins, "The impulse response function and ship motions",
Schiffstechnik 9 (1962) 101–109; T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and
Motion Control*, 2nd ed., 2021, ch. 5) writes the radiation load of a body at rest in the
water as ``−A∞ ν' − ∫₀ᵗ K(t − s) ν(s) ds``, the retardation kernel ``K`` with the transfer
matrix (Fossen 2021, ch. 5; T. Perez and T. I. Fossen, "Time- vs. frequency-domain
identification of parametric radiation force models for marine structures at zero speed",
Modeling, Identification and Control 29 (2008) 1–19)

    K(iω) = B(ω) + iω (A(ω) − A∞).

:func:`fluid_memory` fits it, on the dataset's frequencies, as

    K(s) ≈ Σ_k h_k(s) S_k,

each ``h_k`` a scalar positive-real function and each ``S_k = L_k L_kᵀ`` symmetric positive
semidefinite, so that ``Re K(iω) = Σ_k Re h_k(iω) S_k ⪰ 0`` at every frequency: the fitted memory
is passive whatever the fit's error. Two kinds of ``h_k`` (:data:`BLOCK_KINDS`), each the transfer
function of a small port-Hamiltonian system (so positive real: van der Schaft and Jeltsema,
*Port-Hamiltonian Systems Theory*, 2014, §4.1):

* the oscillator ``h_k(s) = s / (s² + 2ζ_kω_k s + ω_k²)``, ``Re h_k(iω) = 2ζ_kω_k ω² /
  ((ω_k² − ω²)² + (2ζ_kω_kω)²) ≥ 0``: states ``(q, p)``, ``J = [[0, 1], [−1, 0]]``,
  ``R = diag(0, 2ζ_kω_k)``, ``Q = diag(ω_k², 1)``;
* the ladder, two masses in a chain with the damper behind a spring: four states, its
  ``Re h_k(iω)`` falling as ω⁻⁶ (the oscillator's as ω⁻²), as the data's damping does.

Each column ``l`` of each ``L_k`` is one copy of its block driven by ``lᵀν`` (the row of ``G`` of
the driven momentum is ``lᵀ``): ``y = GᵀQx`` has the transfer matrix ``h_k(s) l lᵀ``, and the hull
feels ``−y``.

The degrees of freedom are grouped by the couplings the dataset holds (a coupling whose largest
``|K_ab|`` is below ``coupling_tolerance`` times ``√(max|K_aa| max|K_bb|)`` is dropped); each group
is fitted with its own blocks (:data:`DEFAULT_BLOCKS`, :func:`_fit_group`): the block parameters
by variable projection, the ``S_k`` by (non-negative) linear least squares projected onto the
semidefinite cone, then the parameters and the ``L_k`` together by nonlinear least squares, each
coupling's residual relative to its own largest value.

:func:`with_fluid_memory` gives the vessel with it: its added mass becomes ``A∞`` (Cummins), its
linear damping is kept as the viscous part unless ``damping=`` replaces it, and the subsystem
``radiation`` joins it."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import _core
from ._arguments import checked

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")

#: The couplings the tests and the page report, as (row, column) in DOFS order.
#: The scalar blocks per DOF group by default (:data:`BLOCK_KINDS`; a group not named: two
#: ladders, three for a group of three DOFs or more). Chosen on the shipped box
#: (docs/explanation/components/fluid-memory.md): two ladders per group fit every coupling within
#: 5 % of its largest value, two oscillators the yaw. A hull that is not fore-aft symmetric (the
#: OSV's) joins surge, heave and pitch, and sway, roll and yaw: two ladders each fit its couplings
#: to 10-30 %, three to 3-19 % (the largest, surge-heave, a coupling 2.6 % of surge's own size),
#: four to 3-18 % at 3.6 times the cost (measured on osv_capytaine.nc).
DEFAULT_BLOCKS = {"heave": ["ladder"], "yaw": ["oscillator", "oscillator"],
                  "sway_roll": ["ladder", "ladder", "ladder"], "surge_pitch": ["ladder", "ladder", "oscillator", "oscillator"]}

MAIN_COUPLINGS = ((2, 2), (3, 3), (4, 4), (1, 1), (2, 4), (1, 3))


def _err(msg: str) -> _core.InvalidInputError:
    return _core.InvalidInputError(msg)


def coupling_name(a: int, b: int) -> str:
    return f"{DOFS[a]}-{DOFS[b]}"


@dataclass
class FluidMemory:
    """The result of :func:`fluid_memory`.

    ``table``: the ``[port_hamiltonian]`` table (name ``radiation``); ``added_mass_infinite``:
    the 6×6 ``A∞`` (about the body origin) the vessel takes as ``added_mass``; ``blocks``: per DOF
    group, its blocks ``(kind, parameters)``; ``block_list`` and ``S``: one entry per column of
    the ``L_k`` kept, its block and its rank-one ``l lᵀ`` (6×6), so that ``K(s) = Σ h(s) S``; ``report``: per coupling kept, the relative fit errors (``max``: the
    largest ``|K_fit − K|`` over the dataset's frequencies divided by the largest ``|K|``; ``at``: the
    frequency of that largest error; ``rms``: the same in the root mean square), and ``dropped``: the couplings left out with their size
    relative to the diagonal; ``omega``, ``K``: the dataset's frequencies and its ``K(iω)``;
    ``a_inf_source``: where ``A∞`` came from."""

    table: dict
    added_mass_infinite: np.ndarray
    blocks: dict
    block_list: list
    S: list
    report: dict
    dropped: dict
    omega: np.ndarray
    K: np.ndarray
    a_inf_source: str
    groups: list = field(default_factory=list)

    @property
    def n_states(self) -> int:
        return len(self.table["states"])

    def transfer(self, omega) -> np.ndarray:
        """The fitted ``K(iω)``, shape ``(len(omega), 6, 6)``."""
        return transfer(self.block_list, self.S, omega)

    def report_table(self) -> str:
        """The fit report as a Markdown table (couplings kept, relative errors)."""
        rows = ["| coupling | max \\|K\\| (kg/s or kg m/s, kg m²/s) | max rel. error | at ω (rad/s) | RMS rel. error |",
                "|---|---|---|---|---|"]
        for name, r in self.report.items():
            rows.append(f"| {name} | {r['scale']:.3g} | {r['max']:.3f} | {r['at']:.2f} | {r['rms']:.3f} |")
        return "\n".join(rows)


def h(omega_k: float, zeta_k: float, s):
    """``h_k(s) = s / (s² + 2 ζ_k ω_k s + ω_k²)``: the oscillator block's transfer function."""
    return s / (s * s + 2.0 * zeta_k * omega_k * s + omega_k * omega_k)


#: The two kinds of scalar block, each a port-Hamiltonian system (J skew, R ⪰ 0, Q ≻ 0) driven and
#: read at one state, so its transfer function is positive real: ``(J, R, Q, i)`` from the block's
#: parameters (all > 0), ``i`` the state the input drives and the output reads.
#:
#: * ``oscillator`` (ω, ζ): states (q, p), ``J = [[0, 1], [−1, 0]]``, ``R = diag(0, 2ζω)``,
#:   ``Q = diag(ω², 1)``: ``h(s) = s / (s² + 2ζωs + ω²)``.
#: * ``ladder`` (ω₁, ω₂, m₂, γ; :func:`block_matrices`): two masses in a chain, the first (unit mass) driven, tied to the
#:   ground by the spring k₁ and to the second (mass m₂) by the spring k₁₂, the second held by
#:   the damper c; states (the two springs' elongations, the two momenta). Its dissipation is
#:   behind a spring, so ``Re h(iω)`` falls as ω⁻⁶, where the oscillator's falls as ω⁻².
BLOCK_KINDS = ("oscillator", "ladder")
_LADDER_J = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, -1.0, 1.0], [-1.0, 1.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]])


def block_matrices(kind: str, par) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """``(J, R, Q, i)`` of a block. The ladder's parameters are ``(ω₁, ω₂, m₂, γ)``: ``k₁ = ω₁²``,
    ``k₁₂ = m₂ ω₂²``, ``c = γ m₂`` (so that box bounds on them bound the block's frequencies and its
    decay rate)."""
    if kind not in BLOCK_KINDS:
        raise _err(f"a block's kind must be one of {', '.join(BLOCK_KINDS)}, got {kind!r}")
    if kind == "oscillator":
        wk, zk = par
        return (np.array([[0.0, 1.0], [-1.0, 0.0]]), np.diag([0.0, 2.0 * zk * wk]), np.diag([wk * wk, 1.0]), 1)
    w1, w2, m2, gam = par
    return _LADDER_J.copy(), np.diag([0.0, 0.0, 0.0, gam * m2]), np.diag([w1 * w1, m2 * w2 * w2, 1.0, 1.0 / m2]), 2


def block_transfer(kind: str, par, s) -> np.ndarray:
    """The block's scalar transfer function ``e_iᵀ Q (sI − (J − R) Q)⁻¹ e_i`` at the points ``s``."""
    s = np.asarray(s, dtype=complex)
    if kind == "oscillator":
        return h(par[0], par[1], s)
    J, R, Q, i = block_matrices(kind, par)
    A = (J - R) @ Q
    n = len(A)
    e = np.zeros(n)
    e[i] = 1.0
    X = np.linalg.solve(s[:, None, None] * np.eye(n)[None] - A[None], np.broadcast_to(e, (len(s), n))[..., None])
    return X[..., 0] @ (Q @ e)


def transfer(blocks, S, omega) -> np.ndarray:
    """``Σ_k h_k(iω) S_k`` for ``blocks`` a list of ``(kind, parameters)``."""
    s = 1j * np.asarray(omega, dtype=float)
    out = np.zeros((len(s), 6, 6), dtype=complex)
    for (kind, par), Sk in zip(blocks, S):
        out += block_transfer(kind, par, s)[:, None, None] * np.asarray(Sk)[None]
    return out


@checked
def retardation_data(dataset, *, symmetric: bool = True, checks: str = "refuse", vessel=None,
                     a_inf: str = "dataset"):
    """``(ω, K, A∞, source, loaded)``: the dataset's frequencies, ``K(iω) = B(ω) + iω(A(ω) − A∞)``
    about the body origin (its symmetric part), ``A∞``, where it came from, and what
    :func:`phsplit.hydro.from_capytaine` gave. ``a_inf``: ``"dataset"`` (Capytaine's ``added_mass_infinite_frequency``;
    the highest frequency's ``A`` if the dataset lacks it) or ``"highest"`` (the highest
    frequency's ``A``)."""
    from . import hydro

    out = hydro.from_capytaine(dataset, symmetric=symmetric, checks=checks, vessel=vessel)
    raw = hydro._open(dataset)
    data = hydro._read(raw)          # by increasing frequency, the DOFs in order
    w = np.asarray(data.w, float)
    T = hydro.shift_matrix(out["reference_point"]["shift"])
    A = np.einsum("ji,wjk,kl->wil", T, data.A, T)     # A(ω) about the body origin (Tᵀ A T)
    Bm = np.asarray(out["radiation_damping"], float)
    if a_inf not in ("dataset", "highest"):
        raise _err(f"a_inf must be 'dataset' or 'highest', got {a_inf!r}")
    if a_inf == "dataset" and "added_mass_infinite_frequency" in out:
        Ainf = np.asarray(out["added_mass_infinite_frequency"], float)
        src = "Capytaine's infinite-frequency added mass (added_mass_infinite_frequency)"
    else:
        Ainf = A[-1].copy()
        src = f"the added mass at the highest frequency, {w[-1]:g} rad/s"
    # the symmetric parts: radiation is reciprocal (A, B, A∞ symmetric; Newman 1977, ch. 6); the
    # panels leave an asymmetry (the shipped box: 9 % in A∞'s surge-pitch, 0.3 % in B)
    Ainf = 0.5 * (Ainf + Ainf.T)
    K = Bm + 1j * w[:, None, None] * (A - Ainf[None])
    K = 0.5 * (K + np.transpose(K, (0, 2, 1)))
    return w, K, Ainf, src, out


def _groups(K: np.ndarray, tol: float):
    """Connected groups of DOFs by the couplings kept, and the couplings dropped (relative size)."""
    mag = np.abs(K).max(axis=0)
    diag = np.diag(mag)
    keep = np.zeros((6, 6), bool)
    dropped = {}
    for a in range(6):
        keep[a, a] = True
        for b in range(a + 1, 6):
            ref = math.sqrt(max(diag[a], 0.0) * max(diag[b], 0.0))
            rel = mag[a, b] / ref if ref > 0 else (0.0 if mag[a, b] == 0 else math.inf)
            if rel > tol:
                keep[a, b] = keep[b, a] = True
            else:
                dropped[coupling_name(a, b)] = rel
    seen, groups = set(), []
    for a in range(6):
        if a in seen:
            continue
        stack, g = [a], []
        while stack:
            x = stack.pop()
            if x in seen:
                continue
            seen.add(x)
            g.append(x)
            stack.extend(int(y) for y in np.nonzero(keep[x])[0] if y not in seen)
        groups.append(sorted(g))
    return groups, keep, dropped


def _psd(S: np.ndarray) -> np.ndarray:
    S = 0.5 * (S + S.T)
    ev, V = np.linalg.eigh(S)
    return (V * np.clip(ev, 0.0, None)) @ V.T


def _chol(S: np.ndarray) -> np.ndarray:
    """A lower-triangular L with L Lᵀ = S for a semidefinite S (by its eigen-decomposition)."""
    S = _psd(S)
    m = len(S)
    try:
        return np.linalg.cholesky(S + 1e-14 * max(np.trace(S), 1e-300) * np.eye(m))
    except np.linalg.LinAlgError:
        ev, V = np.linalg.eigh(S)
        Lf = V * np.sqrt(np.clip(ev, 0.0, None))
        _, r = np.linalg.qr(Lf.T)
        return r.T


_NPAR = {"oscillator": 2, "ladder": 4}


def _start(kind, rng, w, first, k, n):
    """A starting point (logarithms of the parameters) for block k of n."""
    if first:
        wk = float(np.geomspace(w.min() * 1.5, w.max(), n)[k]) if n > 1 else math.sqrt(w.min() * w.max())
        return [math.log(wk), math.log(0.5)] if kind == "oscillator" else \
            [math.log(wk), math.log(wk), 0.0, math.log(wk)]
    if kind == "oscillator":
        return [rng.uniform(math.log(w.min()), math.log(2 * w.max())), rng.uniform(math.log(0.1), math.log(1.5))]
    return [rng.uniform(math.log(w.min()), math.log(w.max())), rng.uniform(math.log(w.min()), math.log(w.max())),
            rng.uniform(-1.0, 1.0), rng.uniform(math.log(w.min()), math.log(w.max()))]


def _bounds(kind, w):
    """Box bounds (logarithms): every frequency within [ω_min/2, 3 ω_max], a damping ratio at most
    2, a decay rate at most 3 ω_max, the second mass within [0.1, 5]: no block stiffer than the
    data ask for (a stiff block would cost the splitting's negative sub-steps their stability)."""
    f = (math.log(w.min() / 2), math.log(3 * w.max()))
    if kind == "oscillator":
        return [f, (math.log(0.02), math.log(2.0))]
    return [f, f, (math.log(0.1), math.log(5.0)), (math.log(0.01), math.log(3 * w.max()))]


def _fit_group(w, Kg, pairs, scale, kinds, refine=True, starts=6, seed=0, floor=1.0):
    """Fit one DOF group: ``Kg`` (nω, m, m); ``pairs``: the (i, j), i <= j, kept; ``scale``: each
    pair's largest |K|; ``kinds``: the blocks' kinds. Returns the blocks' parameters and the
    semidefinite S_k (m×m).

    1. The blocks' parameters by variable projection (G. H. Golub and V. Pereyra, SIAM J. Numer.
       Anal. 10 (1973) 413–432): for given parameters the S_k follow by linear least squares
       (non-negative, NNLS, for one DOF; for a group, per entry, then projected onto the
       semidefinite cone), the parameters by ``least_squares`` on the remaining residual, from
       ``starts`` seeded starting points.
    2. For a group, parameters and ``L_k`` (``S_k = L_k L_kᵀ``) together by nonlinear least
       squares, kept if it lowers the residual."""
    from scipy.optimize import least_squares, nnls

    m = Kg.shape[1]
    s = 1j * w
    n = len(kinds)
    tri = [(i, j) for i in range(m) for j in range(i + 1)]
    offs = np.cumsum([0] + [_NPAR[k] for k in kinds])
    npar = int(offs[-1])
    bnd = [b for kd in kinds for b in _bounds(kd, w)]
    lo = np.array([b[0] for b in bnd])
    hi = np.array([b[1] for b in bnd])

    def pars(x):
        return [tuple(np.exp(x[offs[k]:offs[k + 1]])) for k in range(n)]

    def basis(x):
        return np.stack([block_transfer(kd, p, s) for kd, p in zip(kinds, pars(x))], axis=1)  # (nω, n)

    # each residual relative to max(|K_ab(ω)|, floor · max_ω |K_ab|): floor = 1 weighs every
    # frequency alike, a smaller floor weighs where the coupling is small more
    wt = {(i, j): 1.0 / np.maximum(np.abs(Kg[:, i, j]), floor * scale[(i, j)]) for (i, j) in pairs}

    def linear(x):
        H = basis(x)
        Aq = np.vstack([H.real, H.imag])
        S = np.zeros((n, m, m))
        for (i, j) in pairs:
            ww = np.concatenate([wt[(i, j)], wt[(i, j)]])
            bq = np.concatenate([Kg[:, i, j].real, Kg[:, i, j].imag]) * ww
            if m == 1:
                c, _ = nnls(Aq * ww[:, None], bq)
            else:
                c, *_ = np.linalg.lstsq(Aq * ww[:, None], bq, rcond=None)
            S[:, i, j] = S[:, j, i] = c
        return np.array([_psd(Sk) for Sk in S]) if m > 1 else S

    def misfit(x, S):
        F = np.einsum("wk,kij->wij", basis(x), S)
        r = []
        for (i, j) in pairs:
            e = (F[:, i, j] - Kg[:, i, j]) * wt[(i, j)]
            r.append(e.real)
            r.append(e.imag)
        return np.concatenate(r)

    rng = np.random.default_rng(seed)
    best = None
    for t in range(starts):
        x0 = np.concatenate([_start(kd, rng, w, t == 0, k, n) for k, kd in enumerate(kinds)])
        with np.errstate(all="ignore"):
            sol = least_squares(lambda x: misfit(x, linear(x)), np.clip(x0, lo + 1e-9, hi - 1e-9),
                                bounds=(lo, hi), max_nfev=300)
        if np.all(np.isfinite(sol.fun)) and (best is None or sol.cost < best.cost):
            best = sol
    x = best.x
    S = linear(x)
    if not refine or m == 1:
        return pars(x), S

    lscale = np.array([math.sqrt(math.sqrt(scale[(i, i)] * scale[(j, j)])) for (i, j) in tri])

    def unpack(z):
        Ls = z[npar:].reshape(n, len(tri)) * lscale
        out = np.zeros((n, m, m))
        for k in range(n):
            L = np.zeros((m, m))
            for v, (i, j) in zip(Ls[k], tri):
                L[i, j] = v
            out[k] = L @ L.T
        return z[:npar], out

    z0 = np.concatenate([x] + [np.array([_chol(Sk)[i, j] for (i, j) in tri]) / lscale for Sk in S])
    lo2 = np.r_[lo, np.full(len(z0) - npar, -np.inf)]
    hi2 = np.r_[hi, np.full(len(z0) - npar, np.inf)]
    with np.errstate(all="ignore"):
        sol = least_squares(lambda z: misfit(*unpack(z)), np.clip(z0, lo2 + 1e-9, hi2 - 1e-9), bounds=(lo2, hi2),
                            max_nfev=1500)
    if np.all(np.isfinite(sol.fun)) and sol.cost <= 0.5 * float(np.sum(misfit(x, S) ** 2)):
        x, S = unpack(sol.x)
    return pars(x), S


def _check_fit_keywords(blocks, coupling_tolerance, refine, name, rank_tolerance, starts) -> None:
    """The keywords of :func:`fluid_memory`, checked before the dataset is read or a fit begins."""
    import re

    def fraction(key, x):
        if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)) or not (
                math.isfinite(x) and 0.0 <= x < 1.0):
            raise _err(f"{key} must be a number in [0, 1) (relative to the largest entry), got {x!r}")

    fraction("coupling_tolerance", coupling_tolerance)
    fraction("rank_tolerance", rank_tolerance)
    if not isinstance(refine, (bool, np.bool_)):
        raise _err(f"refine must be true or false, got {refine!r}")
    if isinstance(starts, bool) or not isinstance(starts, (int, np.integer)) or not 1 <= starts <= 100:
        raise _err(f"starts must be a whole number of starting points from 1 to 100, got {starts!r}")
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", name):
        raise _err(f"name must be a name of letters, digits and underscores that starts with a letter (it names "
                   f"the subsystem's account and outputs), got {name!r}")
    if blocks is not None and not isinstance(blocks, (int, list, tuple, dict)) or isinstance(blocks, bool):
        raise _err(f"blocks must be a number of oscillators, a list of {', '.join(repr(k) for k in BLOCK_KINDS)}, "
                   f"or a dict from a group's name (e.g. 'sway_roll') to either, got {blocks!r}")
    if isinstance(blocks, dict) and not all(isinstance(k, str) for k in blocks):
        raise _err(f"blocks' keys must be the names of DOF groups (e.g. 'sway_roll'), got {list(blocks)!r}")


def _kinds(spec, gname: str, size: int) -> list[str]:
    if spec is None:
        spec = DEFAULT_BLOCKS
    if isinstance(spec, dict):
        spec = spec.get(gname, DEFAULT_BLOCKS.get(gname, ["ladder"] * (3 if size >= 3 else 2)))
    if isinstance(spec, int) and not isinstance(spec, bool):
        if not 1 <= spec <= 8:
            raise _err(f"blocks for {gname} must be 1 to 8 oscillators, got {spec}")
        return ["oscillator"] * spec
    if not isinstance(spec, (list, tuple)) or not spec or any(k not in BLOCK_KINDS for k in spec) or len(spec) > 8:
        raise _err(f"blocks for {gname} must be a number of oscillators or a list of 1 to 8 of "
                   f"{', '.join(repr(k) for k in BLOCK_KINDS)}, got {spec!r}")
    return list(spec)


@checked
def fluid_memory(dataset, *, symmetric: bool = True, checks: str = "refuse", vessel=None, blocks=None,
                 a_inf: str = "dataset", coupling_tolerance: float = 1e-3, refine: bool = True,
                 name: str = "radiation", rank_tolerance: float = 1e-9, starts: int = 6) -> FluidMemory:
    """Cummins' fluid memory of a Capytaine dataset (a path or an ``xarray.Dataset``), about the
    body origin :func:`phsplit.hydro.from_capytaine` places (``vessel=`` as there): the
    ``[port_hamiltonian]`` table, ``A∞`` and the fit report (:class:`FluidMemory`).

    ``blocks``: the scalar blocks per DOF group (:data:`DEFAULT_BLOCKS`; a number of oscillators,
    a list of kinds from :data:`BLOCK_KINDS`, or a dict from a group's name, e.g. ``"sway_roll"``,
    to either); ``a_inf``: ``"dataset"`` or ``"highest"`` (:func:`retardation_data`);
    ``coupling_tolerance``: the size below which a coupling is dropped (relative to its
    diagonals); ``refine``: refine a group's blocks and residues together by nonlinear least
    squares; ``starts``: the seeded starting points of the fit (deterministic).

    Refused (``InvalidInputError``, naming the coupling): a retardation that is not finite, a DOF
    whose retardation is zero (nothing to fit), a diagonal whose damping is negative at a
    frequency (a memory that would supply energy)."""
    _check_fit_keywords(blocks, coupling_tolerance, refine, name, rank_tolerance, starts)
    w, K, Ainf, src, _ = retardation_data(dataset, symmetric=symmetric, checks=checks, vessel=vessel, a_inf=a_inf)
    if not np.all(np.isfinite(K)):
        _, a, b = np.argwhere(~np.isfinite(K))[0]
        raise _err(f"the retardation K(iw) = B + iw(A - A_inf) of {coupling_name(a, b)} is not finite")
    for a in range(6):
        if not np.abs(K[:, a, a]).max() > 0:
            raise _err(f"the retardation of {coupling_name(a, a)} is zero at every frequency: nothing to fit "
                       f"(is the dataset's {DOFS[a]} radiation problem computed?)")
        neg = np.nonzero(K[:, a, a].real < -1e-6 * np.abs(K[:, a, a]).max())[0]
        if len(neg):
            raise _err(f"the radiation damping of {coupling_name(a, a)} is negative at {w[neg[0]]:g} rad/s "
                       f"({K[neg[0], a, a].real:.4g}): a passive fluid memory cannot fit it")
    groups, keep, dropped = _groups(K, coupling_tolerance)
    gnames = ["_".join(DOFS[a] for a in g) for g in groups]
    if isinstance(blocks, dict):
        unknown = sorted(set(blocks) - set(gnames))
        if unknown:
            raise _err(f"blocks names the group {unknown[0]!r}, which this dataset does not have; its groups of "
                       f"coupled DOFs are {', '.join(gnames)}")
    for g, gname in zip(groups, gnames):  # every group's blocks checked before any is fitted
        _kinds(blocks, gname, len(g))
    all_blocks, S_list, by_group, report = [], [], {}, {}
    states: list[str] = []
    parts = []   # (J, R, Q, i, l6) per column
    for g in groups:
        gname = "_".join(DOFS[a] for a in g)
        kinds = _kinds(blocks, gname, len(g))
        m = len(g)
        Kg = K[:, g][:, :, g]
        pairs = [(i, j) for i in range(m) for j in range(i, m) if keep[g[i], g[j]]]
        scale = {(i, j): float(np.abs(Kg[:, i, j]).max()) for (i, j) in pairs}
        par, S = _fit_group(w, Kg, pairs, scale, kinds, refine, starts=starts)
        by_group[gname] = [(kd, tuple(float(x) for x in p)) for kd, p in zip(kinds, par)]
        for k, (kd, p) in enumerate(zip(kinds, par)):
            ev, V = np.linalg.eigh(_psd(S[k]))
            top = max(float(ev.max()), 0.0)
            cols = [c for c in np.argsort(ev)[::-1] if ev[c] > rank_tolerance * top and ev[c] > 0]
            for r, c in enumerate(cols):
                l6 = np.zeros(6)
                l6[g] = V[:, c] * math.sqrt(ev[c])
                J, R, Q, i = block_matrices(kd, p)
                tag = f"{gname}_{k + 1}" + (f"{'abcdef'[r]}" if m > 1 else "")
                names = ("q", "p") if kd == "oscillator" else ("s1", "s12", "p1", "p2")
                states += [f"{tag}_{x}" for x in names]
                parts.append((J, R, Q, i, l6))
                all_blocks.append((kd, tuple(float(x) for x in p)))
                S_list.append(np.outer(l6, l6))
        for (i, j) in pairs:
            report[coupling_name(g[i], g[j])] = {"scale": scale[(i, j)]}
    nst = len(states)
    J = np.zeros((nst, nst))
    R = np.zeros((nst, nst))
    Q = np.zeros((nst, nst))
    G = np.zeros((nst, 6))
    o = 0
    for (Jb, Rb, Qb, i, l6) in parts:
        nb = len(Jb)
        J[o:o + nb, o:o + nb], R[o:o + nb, o:o + nb], Q[o:o + nb, o:o + nb] = Jb, Rb, Qb
        G[o + i] = l6
        o += nb
    table = {"name": name, "states": states, "input": list(DOFS),
             "J": J.tolist(), "R": R.tolist(), "Q": Q.tolist(), "G": G.tolist()}
    fm = FluidMemory(table=table, added_mass_infinite=Ainf, blocks=by_group, block_list=all_blocks, S=S_list,
                     report=report, dropped=dropped, omega=w, K=K, a_inf_source=src,
                     groups=["_".join(DOFS[a] for a in g) for g in groups])
    # the report from the table's own transfer matrix (the columns kept)
    F = fm.transfer(w)
    for nm in list(report):
        a, b = (DOFS.index(x) for x in nm.split("-"))
        e = np.abs(F[:, a, b] - K[:, a, b]) / report[nm]["scale"]
        report[nm].update(max=float(e.max()), rms=float(np.sqrt(np.mean(e ** 2))), at=float(w[int(np.argmax(e))]))
    return fm


def _added_mass_is_a_models(vessel) -> bool:
    """Whether the vessel's added mass is a shipped vessel's own (a preset's low-frequency added
    mass, which the memory's A∞ replaces, as the shipped osv-weather does), not one of the user's."""
    from .vessel import Vessel, presets

    mine = np.asarray(vessel.to_dict()["vessel"]["added_mass"], float)
    for name in presets():
        theirs = Vessel.preset(name).to_dict()["vessel"].get("added_mass")
        if theirs is not None and np.array_equal(mine, np.asarray(theirs, float)):
            return True
    return False


@checked
def with_fluid_memory(vessel, dataset, *, damping=None, memory: FluidMemory | None = None, symmetric: bool = True,
                      checks: str = "refuse", **fit):
    """The vessel (a ``phsplit.Vessel``) with Cummins' fluid memory of a Capytaine dataset: its
    ``added_mass`` replaced by the dataset's ``A∞`` about its body origin, the subsystem
    ``radiation`` (``[port_hamiltonian]``) added, and its linear damping kept as the viscous
    part, or replaced by ``damping=`` (a dict with ``damping_translational`` and/or
    ``damping_rotational``). ``memory``: a :class:`FluidMemory` from :func:`fluid_memory` of the
    same dataset and vessel (its fit report at hand, no second fit); otherwise the fit is made
    here with the keywords ``fit`` of :func:`fluid_memory`, the dataset checked against the
    vessel's hydrostatics.

    Also :func:`phsplit.radiation.with_fluid_memory`."""
    from .vessel import Vessel

    if not isinstance(vessel, Vessel):
        raise _err(f"with_fluid_memory takes a phsplit.Vessel, got {type(vessel).__name__}")
    d = vessel.to_dict()
    if "port_hamiltonian" in d:
        raise _err(f"the vessel already has a port-Hamiltonian subsystem ({d['port_hamiltonian'].get('name')!r}); "
                   f"a vessel holds one")
    if damping is not None:
        if not isinstance(damping, dict):
            raise _err(f"damping must be a dict (damping_translational and/or damping_rotational), "
                       f"got {type(damping).__name__}")
        bad = sorted(set(damping) - {"damping_translational", "damping_rotational"})
        if bad:
            raise _err(f"damping takes damping_translational and damping_rotational, got {bad[0]!r}")
        for k, x in damping.items():
            try:
                ok = len(x) == 3 and not isinstance(x, (str, bytes)) and all(
                    isinstance(c, (int, float, np.integer, np.floating)) and not isinstance(c, (bool, np.bool_))
                    for c in x)
            except TypeError:
                ok = False
            if not ok:
                raise _err(f"damping[{k!r}] must be 3 numbers (kg/s or kg m^2/s), got {x!r}")
        # The values checked by the core on the vessel they make, before the fit.
        trial = vessel.to_dict()
        for k, x in damping.items():
            trial["vessel"][k] = [float(c) for c in x]
        try:
            Vessel.from_dict(trial)
        except _core.InvalidInputError as e:
            raise _err(f"damping: {e}") from None
    if "added_mass" in d["vessel"] and np.any(np.asarray(d["vessel"]["added_mass"], float) != 0.0) \
            and not _added_mass_is_a_models(vessel):
        raise _err("the vessel gives vessel.added_mass, which the fluid memory replaces by the dataset's "
                   "infinite-frequency added mass: remove it, or start from a shipped vessel")
    known = {"blocks", "a_inf", "coupling_tolerance", "refine", "name", "rank_tolerance", "starts"}
    bad = sorted(set(fit) - known)
    if bad:
        raise _err(f"with_fluid_memory got an unknown keyword {bad[0]!r} (the fit's keywords: {', '.join(sorted(known))})")
    if memory is None:
        memory = fluid_memory(dataset, symmetric=symmetric, checks=checks, vessel=vessel, **fit)
    elif not isinstance(memory, FluidMemory):
        raise _err(f"memory must be the FluidMemory of fluid_memory(), got {type(memory).__name__}")
    elif fit:
        raise _err(f"memory is an existing fit, so the fit's keywords ({', '.join(sorted(fit))}) would not be used: "
                   f"give them to fluid_memory(), or leave memory out")
    else:
        how = "highest" if str(memory.a_inf_source).startswith("the added mass at the highest") else "dataset"
        ainf = retardation_data(dataset, symmetric=symmetric, checks=checks, vessel=vessel, a_inf=how)[2]
        if ainf.shape != memory.added_mass_infinite.shape or not np.allclose(
                memory.added_mass_infinite, ainf, rtol=1e-9, atol=1e-9 * np.abs(ainf).max()):
            raise _err("memory is the fit of another dataset or vessel (its infinite-frequency added mass is not "
                       "this dataset's about this vessel's origin): fit it with fluid_memory() of the same ones")
    d["vessel"]["added_mass"] = memory.added_mass_infinite.tolist()
    if damping is not None:
        for k in ("damping_translational", "damping_rotational"):
            if k in damping:
                d["vessel"][k] = [float(x) for x in damping[k]]
    d["port_hamiltonian"] = memory.table
    return Vessel.from_dict(d, f"{vessel.source} with fluid memory")
