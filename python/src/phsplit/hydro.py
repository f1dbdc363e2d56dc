"""Hydrodynamic data from Capytaine (the open-source BEM solver, https://capytaine.org): a
loader from Capytaine's xarray dataset to phsplit's tables (docs/model.md §5.9), which checks
every dataset before use (docs/hydrodynamic-data.md).

:func:`from_capytaine` takes the dataset that ``capytaine.BEMSolver().fill_dataset`` returns (or
that file written with ``capytaine.io.xarray.separate_complex_values`` and reopened) and gives:

* ``added_mass``: the 6×6 added-mass matrix at the highest computed frequency (the nearest to the
  infinite-frequency value a coarse table has), or at a chosen ``omega``;
* ``added_mass_infinite_frequency``: Capytaine's ``omega = inf`` added mass, when the dataset has
  the variable ``added_mass_infinite_frequency`` (``scripts/gen_capytaine_box.py`` stores it);
* ``radiation_damping``: ``[frequency][6][6]``, on the frequencies of the transfer functions;
* ``hydrostatic_stiffness``: the dataset's 6×6 matrix as stored (about its rotation centre, with
  its centre of mass), and ``reference_point``: the rotation centre, the origin and ``r``;
* ``checks`` (the checks passed, with the measured values) and ``failed_checks``;
* the ``[waves]`` table's transfer-function keys: ``rao_frequencies`` (rad/s),
  ``rao_directions`` (degrees), ``force_rao_real`` and ``force_rao_imag`` (``[direction]
  [frequency][dof]``): the excitation force (Froude–Krylov plus diffraction) per metre of wave
  amplitude. Capytaine writes amplitudes for the time dependence ``e^{−iωt}``, phsplit for
  ``e^{+iωt}``: the loader takes the complex conjugate, which describes the same real force;
* ``drift_coefficients`` (``[direction][frequency][3]``: surge, sway, yaw), when the dataset has
  the variable ``drift_force`` (``omega``, ``wave_direction``, ``drift_dof``) that
  ``scripts/gen_capytaine_box.py`` adds from Capytaine's far-field mean drift. It is real (a
  mean force): no conjugation.

**The reference point.** Capytaine gives every matrix and force about the rotation centre of its
DOFs (the dataset's ``rotation_center``; the shipped datasets: the waterline centre). phsplit's
body origin is the vessel's centre of gravity (``vessel.center_of_gravity`` = 0), or the point
``r_g`` below it. The loader moves added mass, damping, excitation and the drift's yaw moment from
the rotation centre to that origin: with ``r`` from the rotation centre to the origin, the
velocity at the rotation centre is ``v_O = v + ω × (−r) = v + S(r) ω``, i.e. ``ν_O = T ν`` with
``T = [[I, S(r)], [0, I]]`` (Fossen 2021, the system transformation matrix ``H(r)``), so by
virtual work the loads become ``Tᵀ τ`` (``M = M_O − r × F``) and the matrices ``Tᵀ A T``. The
origin is the dataset's ``center_of_mass`` less the vessel's ``r_g``, or ``center_of_gravity=``
given in the dataset's frame (x forward, y to port, z up, metres).

**The checks** (each with its tolerance and source in :data:`TOLERANCES` and
docs/hydrodynamic-data.md): the structure (the variables, coordinates, six DOF labels, drift
labels, dtypes, finiteness, dimensions) always; a bad file is an ``InvalidInputError`` naming the
variable and what was expected. Then the physics: hydrostatics (C33 > 0 and ρgA_wp), the
long-wave limits of the heave force and of the roll and pitch moments, B(ω) symmetric and
positive semidefinite, the Haskind relation between excitation and damping, and, with
``vessel=``, the hydrostatics against the vessel's. A failing dataset is refused
(``checks="refuse"``, the default) with one line naming the check, the DOF, the frequency, the
measured and the expected value; ``checks="warn"`` uses it with a :class:`HydroDataWarning`.

The added mass needs a general mass matrix (``vessel.added_mass``): it is returned, not applied."""
from __future__ import annotations

import math
import os
import warnings

import numpy as np

from . import _core
from ._arguments import checked

DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
DRIFT_DOFS = ("Surge", "Sway", "Yaw")
#: The accepted values of ``checks`` (the scenario key ``hydro_checks``).
CHECK_MODES = ("refuse", "warn")

#: The physics checks' tolerances; docs/hydrodynamic-data.md gives each one's source.
TOLERANCES = {
    # C33 against rho g A_wp when the dataset stores the waterplane area: the same panels' integrals
    "c33_waterplane": 1e-3,
    # the inertia matrix's mass against rho V (Archimedes), when the dataset stores it
    "inertia_mass": 1e-3,
    # the long-wave checks need k sqrt(A_wp) <= 0.2 at the lowest frequency: the neglected terms
    # of the long-wave expansion are O((k l)^2) <= 0.04
    "long_wave_k_l": 0.2,
    # |X3| against rho g A_wp - omega^2 (rho V + A33), in units of rho g A_wp
    "long_wave_heave": 0.05,
    # |X4|, |X5| about the waterline point against k |sin b| C44_b, k |cos b| C55_b (relative)
    "long_wave_moment": 0.10,
    # B(omega): max |B_ij - B_ji| <= 0.02 max |B|, smallest eigenvalue >= -1e-3 max |eigenvalue|
    "damping_symmetry": 0.02,
    "damping_psd": 1e-3,
    # Haskind: |B_jj - B_jj^Haskind| <= 0.15 max_omega B_jj (+ the quadrature's estimated error);
    # frequencies whose quadrature error estimate exceeds 0.02 are not checked for that DOF
    "haskind": 0.15,
    "haskind_quadrature": 0.02,
    # the dataset's hydrostatics against the vessel's: rho, g exactly (1e-6), displacement and
    # C33 within 2 %, C44 and C55 within 10 % (panel-centre quadrature of the waterplane inertia)
    "vessel_rho_g": 1e-6,
    "vessel_displacement": 0.02,
    "vessel_c33": 0.02,
    "vessel_c44_c55": 0.10,
}


class HydroDataWarning(UserWarning):
    """A hydrodynamic dataset failed a physics check and is used because the caller asked for it
    (``checks="warn"``, the scenario key ``hydro_checks = "warn"``)."""


def _err(msg: str) -> _core.InvalidInputError:
    return _core.InvalidInputError(msg)


# -- reading and the structure ------------------------------------------------------------------

def _open(src):
    import xarray as xr

    if isinstance(src, xr.Dataset):
        name = "the Capytaine dataset"
        ds = src
    else:
        if not isinstance(src, (str, os.PathLike)):
            raise _err(f"the Capytaine dataset must be an xarray.Dataset or a path to its NetCDF file, got "
                       f"{type(src).__name__}")
        name = f"the Capytaine dataset {os.fspath(src)!r}"
        if not os.path.exists(src):
            raise _err(f"{name} does not exist")
        # The netCDF-C library reads a truncated classic file as fill values without a word;
        # scipy's reader checks each variable's size. HDF5 (netCDF-4) files go to netCDF4.
        try:
            with open(src, "rb") as fh:
                magic = fh.read(4)
        except OSError as e:
            raise _err(f"cannot read {name}: {e.strerror}") from None
        engine = "scipy" if magic in (b"CDF\x01", b"CDF\x02") else "netcdf4" if magic == b"\x89HDF" else None
        if engine is None:
            raise _err(f"cannot read {name}: it is not a NetCDF file (expected a NetCDF file written by Capytaine, "
                       f"e.g. scripts/gen_capytaine_box.py)")
        try:
            with xr.open_dataset(src, engine=engine) as f:
                ds = f.load()
        except Exception as e:  # any failure to read the file is bad input (truncated, not NetCDF, ...)
            msg = str(e).splitlines()[0] if str(e) else type(e).__name__
            raise _err(f"cannot read {name}: {msg} (truncated or damaged? expected a NetCDF file written by "
                       f"Capytaine, e.g. scripts/gen_capytaine_box.py)") from None
    try:
        ds = ds.load()
    except Exception as e:
        raise _err(f"cannot read {name}: {str(e).splitlines()[0] if str(e) else type(e).__name__}") from None
    return ds


_SINGLETONS = ("g", "rho", "water_depth", "body", "forward_speed")


def _array(ds, name: str, dims: tuple[str, ...], required: bool = True, what: str = ""):
    """The variable ``name`` as a numpy array in the order ``dims`` (complex values joined), its
    dimensions, dtype and finiteness checked; None if absent and not required."""
    if name not in ds.variables:
        if required:
            raise _err(f"the Capytaine dataset lacks {name}{f' ({what})' if what else ''}: compute it with "
                       f"capytaine.BEMSolver().fill_dataset over omega, wave_direction and the six rigid-body DOFs")
        return None
    v = ds[name]
    for d in v.dims:
        if d not in dims and d != "complex" and d in _SINGLETONS and v.sizes[d] == 1:
            v = v.isel({d: 0})
    got = tuple(d for d in v.dims if d != "complex")
    if set(got) != set(dims):
        raise _err(f"the dataset's {name} must have the dimensions ({', '.join(dims)}), got ({', '.join(v.dims)})")
    if not (np.issubdtype(v.dtype, np.number) and not np.issubdtype(v.dtype, np.bool_)):
        raise _err(f"the dataset's {name} must hold numbers, got dtype {v.dtype}")
    if "complex" in v.dims:
        labels = [str(c) for c in ds["complex"].values] if "complex" in ds.coords else []
        if sorted(labels) != ["im", "re"]:
            raise _err(f"the dataset's complex coordinate must be ['re', 'im'], got {labels}")
        if np.issubdtype(v.dtype, np.complexfloating):
            raise _err(f"the dataset's {name} has a complex dimension and complex values; expected real parts")
        v = v.sel(complex="re") + 1j * v.sel(complex="im")
    a = np.asarray(v.transpose(*dims).values)
    bad = ~np.isfinite(a)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        at = ", ".join(f"{d} = {_label(ds, d, i)}" for d, i in zip(dims, idx))
        raise _err(f"the dataset's {name} holds a non-finite value ({a[idx]}) at {at or 'its only entry'}")
    return a


def _label(ds, dim, i):
    if dim in ds.coords:
        x = ds[dim].values[i]
        return f"{x:g}" if isinstance(x, (float, np.floating)) else str(x)
    return str(i)


def _coord(ds, name: str, what: str) -> np.ndarray:
    if name not in ds.coords and name not in ds.variables:
        raise _err(f"the Capytaine dataset lacks the coordinate {name} ({what})")
    v = ds[name]
    if v.ndim != 1:
        raise _err(f"the dataset's {name} must be one-dimensional, got dimensions {v.dims}")
    return np.asarray(v.values)


def _numbers(ds, name: str, what: str, finite: bool = True) -> np.ndarray:
    a = _coord(ds, name, what)
    if not (np.issubdtype(a.dtype, np.number) and not np.issubdtype(a.dtype, np.bool_)) or np.iscomplexobj(a):
        raise _err(f"the dataset's {name} must hold real numbers ({what}), got dtype {a.dtype}")
    a = a.astype(float)
    if finite and not np.all(np.isfinite(a)):
        raise _err(f"the dataset's {name} must be finite ({what}), got {a.tolist()}")
    if len(np.unique(a)) != len(a):
        raise _err(f"the dataset's {name} repeats a value: {a.tolist()}")
    return a


def _labels(ds, name: str, want: tuple[str, ...]) -> None:
    got = [str(x) for x in _coord(ds, name, "the DOF labels")]
    if sorted(got) != sorted(want):
        raise _err(f"the dataset's {name} must be the labels {', '.join(want)}, got {', '.join(got) or 'none'}")


def _scalar(ds, name: str, what: str, positive: bool = True, allow_inf: bool = False) -> float:
    if name not in ds.variables:
        raise _err(f"the Capytaine dataset lacks {name} ({what})")
    a = np.asarray(ds[name].values)
    if a.size != 1 or not (np.issubdtype(a.dtype, np.number) and not np.issubdtype(a.dtype, np.bool_)) \
            or np.iscomplexobj(a):
        raise _err(f"the dataset's {name} must be one real number ({what}), got {a.tolist()!r}")
    x = float(a.reshape(-1)[0])
    if math.isnan(x) or (math.isinf(x) and not allow_inf) or (positive and not x > 0):
        raise _err(f"the dataset's {name} must be a number > 0 ({what}), got {x:g}")
    return x


def _point(ds, name: str, what: str) -> np.ndarray:
    if name not in ds.variables:
        raise _err(f"the Capytaine dataset lacks {name} ({what}; Capytaine writes it as a coordinate "
                   f"over space_coordinate)")
    v = ds[name]
    if "body" in v.dims:
        if v.sizes["body"] != 1:
            raise _err(f"the dataset holds {v.sizes['body']} bodies; phsplit reads one")
        v = v.isel(body=0)
    a = np.asarray(v.values)
    if v.dims != ("space_coordinate",) or a.shape != (3,) or not np.issubdtype(a.dtype, np.number) \
            or not np.all(np.isfinite(a.astype(float))):
        raise _err(f"the dataset's {name} must be three finite numbers over space_coordinate (x, y, z), "
                   f"got {a.tolist()!r}")
    if "space_coordinate" in ds.coords and [str(c) for c in ds["space_coordinate"].values] != ["x", "y", "z"]:
        raise _err(f"the dataset's space_coordinate must be x, y, z, got {[str(c) for c in ds['space_coordinate'].values]}")
    return a.astype(float)


class _Data:
    """The dataset's numbers, checked for structure, in DOFS order, by increasing frequency."""


def _read(ds) -> _Data:
    has_exc = "excitation_force" in ds.variables or {"Froude_Krylov_force", "diffraction_force"} <= set(ds.variables)
    missing = [n for n in ("added_mass", "omega", "wave_direction", "influenced_dof", "radiating_dof")
               if n not in ds.variables]
    if not has_exc:
        missing.append("excitation_force (or Froude_Krylov_force and diffraction_force)")
    if missing:
        raise _err(f"the Capytaine dataset lacks {', '.join(missing)}: compute it with capytaine.BEMSolver()"
                   f".fill_dataset over omega, wave_direction and the six rigid-body DOFs")
    d = _Data()
    w = _numbers(ds, "omega", "the frequencies, rad/s")
    if len(w) < 2 or not np.all(w > 0):
        raise _err(f"the dataset's omega must hold at least two frequencies > 0 rad/s (store the infinite-frequency "
                   f"added mass as added_mass_infinite_frequency), got {w.tolist()}")
    beta = _numbers(ds, "wave_direction", "the waves' propagation directions, rad")
    _labels(ds, "influenced_dof", DOFS)
    _labels(ds, "radiating_dof", DOFS)
    sel = {"influenced_dof": list(DOFS), "radiating_dof": list(DOFS)}
    ds = ds.sel(**sel)
    mat = ("omega", "influenced_dof", "radiating_dof")
    frc = ("omega", "wave_direction", "influenced_dof")
    d.A = _array(ds, "added_mass", mat).real
    d.B = _array(ds, "radiation_damping", mat, what="the radiation damping").real
    if "excitation_force" in ds.variables:
        d.X = _array(ds, "excitation_force", frc)
    else:
        d.X = _array(ds, "Froude_Krylov_force", frc) + _array(ds, "diffraction_force", frc)
    d.FK = _array(ds, "Froude_Krylov_force", frc, required=False)
    ainf = _array(ds, "added_mass_infinite_frequency", ("influenced_dof", "radiating_dof"), required=False)
    d.Ainf = None if ainf is None else ainf.real
    d.C = _array(ds, "hydrostatic_stiffness", ("influenced_dof", "radiating_dof"),
                 what="the hydrostatic stiffness; Capytaine stores it when the body has a centre of mass").real
    mi = _array(ds, "inertia_matrix", ("influenced_dof", "radiating_dof"), required=False)
    d.M = None if mi is None else mi.real
    d.drift = None
    if "drift_force" in ds.variables:
        _labels(ds, "drift_dof", DRIFT_DOFS)
        d.drift = _array(ds.sel(drift_dof=list(DRIFT_DOFS)), "drift_force", ("omega", "wave_direction", "drift_dof"))
        if np.iscomplexobj(d.drift):
            if np.abs(d.drift.imag).max() > 0:
                raise _err("the dataset's drift_force must be real (a mean force)")
            d.drift = d.drift.real
    for name, a in (("added_mass", d.A), ("radiation_damping", d.B)):
        if np.iscomplexobj(a):
            raise _err(f"the dataset's {name} must be real")
    d.rho = _scalar(ds, "rho", "the water density, kg/m^3")
    d.g = _scalar(ds, "g", "the acceleration of gravity, m/s^2")
    d.depth = _scalar(ds, "water_depth", "the water depth, m", allow_inf=True)
    if not math.isinf(d.depth):
        raise _err(f"the dataset's water_depth is {d.depth:g} m: phsplit's waves are deep-water (water_depth = inf)")
    d.rc = _point(ds, "rotation_center", "the point the rotations and moments are taken about")
    d.cm = _point(ds, "center_of_mass", "the centre of gravity the hydrostatic stiffness was computed with")
    d.awp = float(ds["waterplane_area"].values) if "waterplane_area" in ds.variables else None
    d.cb = _point(ds, "center_of_buoyancy", "the centre of buoyancy") if "center_of_buoyancy" in ds.variables else None
    if "disp_volume" in ds.variables:
        d.vol = _scalar(ds, "disp_volume", "the displaced volume, m^3")
    elif "disp_mass" in ds.variables:
        d.vol = _scalar(ds, "disp_mass", "the displaced mass, kg") / d.rho
    else:
        raise _err("the Capytaine dataset lacks disp_volume or disp_mass (the displacement; Capytaine's hydrostatics)")
    if d.awp is not None and not (math.isfinite(d.awp) and d.awp > 0):
        raise _err(f"the dataset's waterplane_area must be a number > 0 (m^2), got {d.awp:g}")
    order = np.argsort(w)
    d.w, d.beta = w[order], beta
    d.A, d.B, d.X = d.A[order], d.B[order], d.X[order]
    d.FK = None if d.FK is None else d.FK[order]
    d.drift = None if d.drift is None else d.drift[order]
    return d


# -- the physics checks -------------------------------------------------------------------------

def _full_circle(beta: np.ndarray, X: np.ndarray, symmetric: bool):
    """|X|^2 on the full circle of directions: (directions, |X|^2 [omega][direction][dof]), the
    mirror image of (0, pi) added for a port-starboard symmetric hull (|X_j(-b)| = |X_j(b)|)."""
    b = np.mod(beta, 2 * np.pi)
    x2 = np.abs(X) ** 2
    if symmetric:
        inner = (b > 1e-9) & (b < np.pi - 1e-9)
        b = np.concatenate([b, 2 * np.pi - b[inner]])
        x2 = np.concatenate([x2, x2[:, inner]], axis=1)
    o = np.argsort(b)
    b, x2 = b[o], x2[:, o]
    keep = np.concatenate([[True], np.diff(b) > 1e-9]) & (b < 2 * np.pi - 1e-9)
    return b[keep], x2[:, keep]


def _check(d: _Data, symmetric: bool, vessel: dict | None) -> tuple[list[str], list[str]]:
    """(failures, notes): one line per failed check, and the checks passed or not applicable."""
    fail: list[str] = []
    note: list[str] = []
    rho, g, w = d.rho, d.g, d.w
    rg = rho * g
    C = d.C
    # hydrostatics
    awp = d.awp if d.awp is not None else C[2, 2] / rg
    if not C[2, 2] > 0:
        fail.append(f"hydrostatics: C33 = {C[2, 2]:.4g} N/m, expected > 0 (rho g A_wp)")
    elif d.awp is not None and abs(C[2, 2] - rg * d.awp) > TOLERANCES["c33_waterplane"] * C[2, 2]:
        fail.append(f"hydrostatics: C33 = {C[2, 2]:.6g} N/m, expected rho g A_wp = {rg * d.awp:.6g} N/m "
                    f"(within {TOLERANCES['c33_waterplane']:g})")
    else:
        note.append(f"hydrostatics: C33 = {C[2, 2]:.6g} N/m = rho g A_wp, A_wp = {awp:.6g} m^2")
    if d.M is not None:  # a floating body's mass is its displacement (Archimedes)
        if abs(d.M[0, 0] - rho * d.vol) > TOLERANCES["inertia_mass"] * rho * d.vol:
            fail.append(f"inertia: the inertia matrix's mass is {d.M[0, 0]:.6g} kg, expected the displacement rho V = "
                        f"{rho * d.vol:.6g} kg (rho = {rho:g} kg/m^3; within {TOLERANCES['inertia_mass']:g})")
        else:
            note.append(f"inertia: mass {d.M[0, 0]:.6g} kg = rho V")
    # long waves
    i0 = 0
    k0 = w[i0] ** 2 / g
    kl = k0 * math.sqrt(max(awp, 0.0))
    beta = d.beta
    if not awp > 0:
        fail.append("long waves: no waterplane area (C33 <= 0), so no long-wave reference")
    elif kl > TOLERANCES["long_wave_k_l"]:
        fail.append(f"long waves: the lowest frequency {w[i0]:g} rad/s has k sqrt(A_wp) = {kl:.3g}, expected "
                    f"<= {TOLERANCES['long_wave_k_l']:g} (the table must reach long waves)")
    else:
        ref = rg * awp - w[i0] ** 2 * (rho * d.vol + d.A[i0, 2, 2])
        dev = (np.abs(d.X[i0, :, 2]) - ref) / (rg * awp)
        j = int(np.argmax(np.abs(dev)))
        msg = (f"|X3| = {abs(d.X[i0, j, 2]) / (rg * awp):.4g} rho g A_wp at {w[i0]:g} rad/s, "
               f"{math.degrees(beta[j]):g} deg, expected rho g A_wp - omega^2 (rho V + A33) = {ref / (rg * awp):.4g} "
               f"rho g A_wp (long-wave limit 1)")
        if abs(dev[j]) > TOLERANCES["long_wave_heave"]:
            fail.append(f"long-wave heave: {msg}, within {TOLERANCES['long_wave_heave']:g}")
        else:
            note.append(f"long-wave heave: {msg}")
        # moments about the waterline point W below the rotation centre O: M_W = M_O - (W - O) x F
        r = np.array([0.0, 0.0, -d.rc[2]])
        F, M = d.X[i0, :, 0:3], d.X[i0, :, 3:6]
        MW = M - np.cross(r, F)
        # the pressure part of the restoring about W (the weight does not feel the waves):
        # C_b = C(O) + m g (z_G - z_O) + rho g V z_O = C(O) + rho g V z_G with m = rho V
        cb = {3: C[3, 3] + rg * d.vol * d.cm[2], 4: C[4, 4] + rg * d.vol * d.cm[2]}
        # To the same order in k the diffraction adds the added mass times the waves' horizontal
        # acceleration at the waterline, g times the surface's slope: with the dataset's signs
        # (Capytaine's, z up) the slope's factor is C_b - g A[n, h], h the horizontal DOF the
        # moment couples with (sway for roll, surge for pitch). And a heave force off the
        # waterline point (a centre of flotation or of buoyancy off it) gives a moment of order 1,
        # in quadrature with that: rho g A_wp - omega^2 (rho V + A33) acting at the centre of
        # flotation, at the centre of buoyancy and through A[n, heave] (J. N. Newman, Marine
        # Hydrodynamics, 1977, §6.13: the long-wave excitation is the Froude-Krylov force plus the
        # added mass times the fluid's acceleration). Measured on the shipped datasets, |X| over
        # that is 0.96-1.02 (roll, pitch), the Froude-Krylov part alone 1.39 for the OSV's roll.
        AW = shift_matrix(r).T @ d.A[i0] @ shift_matrix(r)
        # the centre of buoyancy's horizontal offsets (the same from the rotation centre and from W)
        xb = d.cb - d.rc if d.cb is not None else np.zeros(3)
        w2 = w[i0] ** 2
        in_phase = {3: C[3, 2] - w2 * (rho * d.vol * xb[1] + AW[3, 2]),
                    4: C[4, 2] + w2 * (rho * d.vol * xb[0] - AW[4, 2])}
        slope = {3: cb[3] - g * AW[3, 1], 4: cb[4] - g * AW[4, 0]}
        for n, (dof, trig) in {3: ("roll", np.sin), 4: ("pitch", np.cos)}.items():
            s = np.abs(trig(beta))
            use = s >= 0.5
            if not use.any():
                fail.append(f"long-wave {dof}: no direction with |{trig.__name__} b| >= 0.5 to check it in")
                continue
            if not cb[n] > 0:
                fail.append(f"long-wave {dof}: the restoring's pressure part C{n + 1}{n + 1} + rho g V z_G = "
                            f"{cb[n]:.4g} N m, expected > 0")
                continue
            ratio = np.abs(MW[use, n - 3]) / np.hypot(in_phase[n], k0 * s[use] * slope[n])
            j = int(np.argmax(np.abs(ratio - 1)))
            bj = math.degrees(beta[use][j])
            h = "sway" if n == 3 else "surge"
            msg = (f"|X{n + 1}| = {ratio[j]:.4g} |k {trig.__name__} b (C{n + 1}{n + 1} + rho g V z_G "
                   f"- g A[{dof},{h}]) + i (the heave force's moment)| at {w[i0]:g} rad/s, {bj:g} deg, "
                   f"about the waterline point, expected 1")
            if abs(ratio[j] - 1) > TOLERANCES["long_wave_moment"]:
                fail.append(f"long-wave {dof}: {msg} within {TOLERANCES['long_wave_moment']:g}")
            else:
                note.append(f"long-wave {dof}: {msg}")
    # B(omega) symmetric, positive semidefinite
    worst_asym, worst_eig = (0.0, 0), (0.0, 0)
    for i in range(len(w)):
        B = d.B[i]
        scale = np.abs(B).max()
        if scale == 0:
            continue
        asym = np.abs(B - B.T).max() / scale
        ev = np.linalg.eigvalsh(0.5 * (B + B.T))
        lam = ev.min() / np.abs(ev).max()
        if asym > worst_asym[0]:
            worst_asym = (asym, i)
        if lam < worst_eig[0]:
            worst_eig = (lam, i)
    if worst_asym[0] > TOLERANCES["damping_symmetry"]:
        i = worst_asym[1]
        a, b = np.unravel_index(np.argmax(np.abs(d.B[i] - d.B[i].T)), (6, 6))
        fail.append(f"damping symmetry: B at {w[i]:g} rad/s has B[{DOFS[a]},{DOFS[b]}] = {d.B[i][a, b]:.4g} and "
                    f"B[{DOFS[b]},{DOFS[a]}] = {d.B[i][b, a]:.4g}, expected equal within "
                    f"{TOLERANCES['damping_symmetry']:g} max|B|")
    else:
        note.append(f"damping symmetry: max |B - B^T| / max |B| = {worst_asym[0]:.2g}")
    if worst_eig[0] < -TOLERANCES["damping_psd"]:
        i = worst_eig[1]
        neg = [DOFS[j] for j in range(6) if d.B[i][j, j] < 0]
        fail.append(f"damping positive semidefinite: B at {w[i]:g} rad/s has the eigenvalue {worst_eig[0]:.3g} "
                    f"max|eig|" + (f" (negative diagonal: {', '.join(neg)})" if neg else "")
                    + f", expected >= -{TOLERANCES['damping_psd']:g} max|eig|")
    else:
        note.append(f"damping positive semidefinite: smallest eigenvalue {worst_eig[0]:.2g} max|eig|")
    # Haskind (deep water): B_jj = omega^3 / (4 pi rho g^3) * integral of |X_j|^2 over the circle
    b, x2 = _full_circle(d.beta, d.X, symmetric)
    n = len(b)
    h = 2 * np.pi / max(n, 1)
    uniform = n >= 4 and n % 2 == 0 and np.allclose(np.diff(np.concatenate([b, [b[0] + 2 * np.pi]])), h, atol=1e-6)
    if not uniform:
        fail.append(f"Haskind: the directions {np.round(np.degrees(b), 3).tolist()} deg are not an even number "
                    f"of equally spaced directions over the full circle" +
                    ("" if symmetric else " (for a port-starboard symmetric hull over [0, 180] deg: symmetric = true)"))
    else:
        fine = h * x2.sum(axis=1)
        coarse = 2 * h * x2[:, 0::2].sum(axis=1)
        qerr = np.abs(fine - coarse) / np.where(fine > 0, fine, 1.0)
        BH = w[:, None] ** 3 / (4 * np.pi * rho * g ** 3) * fine
        worst, skipped = None, []
        for j in range(6):
            peak = max(d.B[:, j, j].max(), 0.0)
            for i in range(len(w)):
                if qerr[i, j] > TOLERANCES["haskind_quadrature"]:
                    skipped.append((DOFS[j], w[i]))
                    continue
                tol = TOLERANCES["haskind"] * peak + qerr[i, j] * BH[i, j]
                dev = abs(d.B[i, j, j] - BH[i, j])
                if worst is None or dev - tol > worst[0]:
                    worst = (dev - tol, i, j, tol)
        if worst is not None and worst[0] > 0:
            _, i, j, tol = worst
            fail.append(f"Haskind: B[{DOFS[j]},{DOFS[j]}] at {w[i]:g} rad/s is {d.B[i, j, j]:.4g}, expected from the "
                        f"excitation {BH[i, j]:.4g} (omega^3/(4 pi rho g^3) times the integral of |X|^2) within "
                        f"{tol:.3g} ({TOLERANCES['haskind']:g} of the largest B[{DOFS[j]},{DOFS[j]}])")
        else:
            note.append(f"Haskind: B_jj against the excitation within {TOLERANCES['haskind']:g} of each DOF's largest "
                        f"damping, {n} directions" + (f"; not checked where the quadrature's error estimate exceeds "
                                                     f"{TOLERANCES['haskind_quadrature']:g}: " +
                                                     ", ".join(f"{dof} {x:g}" for dof, x in skipped) if skipped else ""))
    # against the vessel
    if vessel is not None:
        p = vessel
        m, awp_v = float(p["mass"]), float(p["waterplane_area"])
        rho_v, g_v = float(p["water_density"]), float(p["gravity"])
        t = TOLERANCES
        for name, got, want in (("rho", rho, rho_v), ("g", g, g_v)):
            if abs(got - want) > t["vessel_rho_g"] * want:
                fail.append(f"vessel: the dataset's {name} = {got:g}, the vessel's {want:g}")
        checks = [("displacement rho V", rho * d.vol, m, t["vessel_displacement"], "kg"),
                  ("C33", C[2, 2], rho_v * g_v * awp_v, t["vessel_c33"], "N/m"),
                  ("C44", C[3, 3], m * g_v * float(p["gm_transverse"]), t["vessel_c44_c55"], "N m"),
                  ("C55", C[4, 4], m * g_v * float(p["gm_longitudinal"]), t["vessel_c44_c55"], "N m")]
        for name, got, want, tol, unit in checks:
            if not abs(got - want) <= tol * abs(want):
                fail.append(f"vessel: the dataset's {name} = {got:.5g} {unit}, the vessel's {want:.5g} {unit} "
                            f"(within {tol:g})")
            else:
                note.append(f"vessel: {name} {got:.5g} against {want:.5g} {unit}")
    return fail, note


# -- the reference point ------------------------------------------------------------------------

def shift_matrix(r) -> np.ndarray:
    """``T = [[I, S(r)], [0, I]]``: generalised velocities at a point P to those at the point O
    with ``r = P − O`` (``v_O = v_P + S(r) ω``, ``S(r) ω = r × ω``); loads go from O to P as
    ``Tᵀ τ`` and matrices as ``Tᵀ A T`` (Fossen 2021, the system transformation matrix H(r))."""
    try:
        r = np.asarray(r, dtype=float)
    except (TypeError, ValueError):
        r = np.full(1, np.nan)
    if r.shape != (3,) or not np.all(np.isfinite(r)):
        raise _err("shift_matrix: r must be three finite numbers (m, the point's offset), got "
                   f"{r.tolist() if r.ndim else r!r}")
    s = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    t = np.eye(6)
    t[0:3, 3:6] = s
    return t


def _vessel_params(vessel):
    if vessel is None:
        return None, np.zeros(3)
    d = vessel.to_dict() if hasattr(vessel, "to_dict") else vessel
    if not isinstance(d, dict):
        raise _err(f"vessel must be a phsplit.Vessel or its dict, got {type(vessel).__name__}")
    p = d.get("vessel", d)
    need = ("mass", "waterplane_area", "water_density", "gravity", "gm_transverse", "gm_longitudinal")
    miss = [k for k in need if k not in p]
    if miss:
        raise _err(f"the vessel lacks {', '.join(miss)} (needed to check the hydrodynamic data against it)")
    return p, np.asarray(p.get("center_of_gravity", [0.0, 0.0, 0.0]), dtype=float)


# -- the loader ---------------------------------------------------------------------------------

@checked
def from_capytaine(ds, omega: float | None = None, symmetric: bool = False, *, checks: str | None = "refuse",
                   vessel=None, center_of_gravity=None) -> dict:
    """phsplit's tables from a Capytaine dataset (an ``xarray.Dataset`` or a path to its NetCDF
    file), moved to the vessel's body origin and checked (module docs).

    ``symmetric=True`` mirrors directions in (0, 180) degrees to (180, 360) for a hull
    symmetric about its x–z plane (sway, roll and yaw change sign). ``checks``: ``"refuse"``
    (default) or ``"warn"``. ``vessel``: a ``phsplit.Vessel`` (or its dict) whose hydrostatics
    the dataset must match and whose ``center_of_gravity`` places the body origin.
    ``center_of_gravity``: the body origin in the dataset's frame (default: the dataset's
    ``center_of_mass``, less the vessel's ``center_of_gravity``)."""
    if checks is None:
        checks = "refuse"
    if not isinstance(checks, str) or checks not in CHECK_MODES:
        raise _err(f"hydro_checks must be one of {', '.join(repr(c) for c in CHECK_MODES)}, got {checks!r}")
    if not isinstance(symmetric, bool):
        raise _err(f"symmetric must be true or false, got {symmetric!r}")
    if center_of_gravity is not None:
        try:
            cg = np.asarray(center_of_gravity, dtype=float)
        except (TypeError, ValueError):
            cg = np.full(1, np.nan)
        if cg.shape != (3,) or not np.all(np.isfinite(cg)):
            raise _err(f"center_of_gravity must be three finite numbers (m, the dataset's frame), got "
                       f"{center_of_gravity!r}")
    params, r_g = _vessel_params(vessel)
    raw = _open(ds)
    d = _read(raw)
    w = d.w
    if omega is not None and not (isinstance(omega, (int, float)) and not isinstance(omega, bool)
                                  and float(w.min()) <= float(omega) <= float(w.max())):
        raise _err(f"omega must lie within the dataset's frequencies [{w.min():g}, {w.max():g}] rad/s, got {omega!r}")
    fail, note = _check(d, symmetric, params)
    if fail:
        head = (f"the hydrodynamic data fail {len(fail)} physics check{'s' if len(fail) > 1 else ''} "
                f"(docs/hydrodynamic-data.md): " + "; ".join(fail))
        if checks == "refuse":
            raise _err(head + " (to use them anyway: hydro_checks = \"warn\"; checks=\"warn\" in Python)")
        warnings.warn(head + " -- used anyway (hydro_checks = \"warn\")", HydroDataWarning, stacklevel=2)
    # the reference point
    if center_of_gravity is None:
        origin = d.cm - r_g
    else:
        origin = np.asarray(center_of_gravity, dtype=float) - r_g
    r = origin - d.rc
    T = shift_matrix(r)
    A = T.T @ d.A @ T
    Bm = T.T @ d.B @ T
    Ainf = None if d.Ainf is None else T.T @ d.Ainf @ T
    X = np.einsum("ji,wbj->wbi", T, d.X)  # T^T X for each frequency and direction
    if omega is None:
        added = A[-1]
    else:
        added = np.array([[np.interp(float(omega), w, A[:, a, b]) for b in range(6)] for a in range(6)])
    f = np.conj(np.transpose(X, (1, 0, 2)))  # [direction][frequency][dof]; e^{-iωt} -> e^{+iωt}
    dirs = np.degrees(d.beta)
    if symmetric:
        sign = np.array([1, -1, 1, -1, 1, -1])
        extra = [(360.0 - x, f[i] * sign) for i, x in enumerate(dirs) if 0.0 < x < 180.0]
        dirs = np.concatenate([dirs, [x for x, _ in extra]])
        f = np.concatenate([f, np.array([x for _, x in extra]).reshape(-1, *f.shape[1:])])
    d_order = np.argsort(dirs)
    dirs, f = dirs[d_order], f[d_order]
    waves = {"rao_frequencies": w.tolist(), "rao_directions": dirs.tolist(),
             "force_rao_real": f.real.tolist(), "force_rao_imag": f.imag.tolist()}
    if d.drift is not None:
        dr = np.transpose(d.drift, (1, 0, 2)).copy()  # [direction][frequency][surge, sway, yaw]
        dr[..., 2] -= r[0] * dr[..., 1] - r[1] * dr[..., 0]  # N_P = N_O - (r x F)_z
        if symmetric:
            base = np.degrees(d.beta)
            extra = [dr[i] * np.array([1, -1, -1]) for i, x in enumerate(base) if 0.0 < x < 180.0]
            dr = np.concatenate([dr, np.array(extra).reshape(-1, *dr.shape[1:])])
        waves["drift_coefficients"] = dr[d_order].tolist()
    out = {"added_mass": added, "radiation_damping": Bm, "hydrostatic_stiffness": d.C, "waves": waves,
           "reference_point": {"rotation_center": d.rc.tolist(), "origin": origin.tolist(), "shift": r.tolist()},
           "checks": note, "failed_checks": fail}
    if Ainf is not None:
        out["added_mass_infinite_frequency"] = Ainf
    return out
