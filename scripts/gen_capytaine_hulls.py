"""Compute the hydrodynamic data of a ship-like hull for the `osv` vessel preset with Capytaine
(the open-source BEM solver) and store them as NetCDF (python/src/phsplit/scenarios/
osv_capytaine.nc), with a Capytaine-computed RAO of the preset as a peer reference for the tests
(python/tests/data/osv_capytaine_rao.nc).

Run: `make capytaine-hulls` (it installs Capytaine into .venv-capytaine, as `make capytaine-box`).
A few minutes on one core.

The computation is the one of scripts/gen_capytaine_box.py (its docstring and
docs/hydrodynamic-data.md; its constants and Kochin directions are imported from it): the wetted
hull only (no panels in the free surface), an interior lid below the free surface against the
irregular frequencies (Capytaine's documentation, "Irregular frequencies"), rho = 1025 kg/m^3,
g = 9.81 m/s^2, infinite depth, six rigid-body DOFs about the waterline point at midships (MSS's
CO, the preset's body origin), the centre of mass stored (the preset's CG), added mass and
damping, A(inf) (`added_mass_infinite_frequency`), excitation and Froude-Krylov forces, the
hydrostatics, the far-field mean drift (`drift_force`).

**The hull** (no lines plan of osv.m's vessel is published; the hull is a parametric one fitted to
the preset's published inputs, MSS osv.m, github.com/cybergalactic/MSS, CRAFT/SHIP/models/osv.m,
as collected in crates/phsplit-core/data/vessels/osv.toml and docs/research/mss_vessels.md §1):
L = 83 m, B = 18 m, T = 5 m, Cb = 0.65, Cw = 0.8, LCF = -0.5 m, CG = (-4.5, 0, 1.2) m (z up from
the CO), mass rho Cb L B T, GM_T = 2.0658 m (Munro-Smith's waterplane inertia and Morrish's KB),
GM_L = 120.26 m. With u = 2x/L and s = -z/T, the half-breadth is

    y(x, z) = B/2 f(u) g(s, u),   g = 1 - s^q(u),

* the waterline f: forward, the full beam from midships to u = a_f (a parallel body), then a
  taper 1 - v^p_f (fitted: straight, p_f = 1) to a vertical stem (f(1) = 0); aft (u < -a_a), a
  taper 1 - (1 - t) v^p_a (fitted: a_a = 0, straight) to a transom of width t B (a flat, vertical
  transom panel, the full draught deep);
* the sections g: q(u) piecewise linear in u, q_aft at the transom, q_mid at midships, q_fore at
  the stem -- box-like sections aft, V-shaped ones forward; a sharp keel (g(1) = 0).

The parameters are a least-squares fit (`python scripts/gen_capytaine_hulls.py --fit`, in the
Capytaine environment) of the panelled hull's own hydrostatics to rho V = the preset's mass,
A_wp = 1.01 Cw L B, LCF = -0.5 m, LCB = LCG = -4.5 m (the preset's equilibrium: osv.m's
r_bb = r_bg in x), GM_T and GM_L, with straight or convex waterlines (p >= 1) and q_fore >= 0.7;
then the three section exponents are scaled by a common factor (bisection) so that the panelled
volume is the preset's mass / rho within 1e-4 (the loader checks the stored inertia's mass, the
preset's, against rho V within 1e-3).

The preset's numbers are mutually inconsistent for any monotone waterline of this family:
Munro-Smith's transverse coefficient 0.656 and osv.m's longitudinal one of 0.70 (GM_L = 120.26 m)
at Cw = 0.8 need a waterplane both spread (f^3) and full at the ends. The fit's compromise, as
panelled and computed by Capytaine (the file's attribute `hydrostatics`): displacement exact,
A_wp 1212.65 m^2 (+1.5 %), GM_T 1.944 m (-5.9 %), GM_L 109.95 m (-8.6 %) -- within the
loader's tolerances (C33 2 %, C44 and C55 10 %) but GM_L with little margin --, KB 2.86 m,
LCF -0.72 m, LCB -3.97 m (0.53 m forward of the CG, so Capytaine's stiffness has a roll-yaw term
rho g V (x_G - x_B) = -2.6e7 N m), a 0.61 B wide transom the full draught deep, and concave V
sections at the stem (q_fore = 0.7).

**The loader's long-wave roll and pitch checks** include the diffraction's term and the heave
force's moment off the waterline point (docs/hydrodynamic-data.md): at 0.2 rad/s the roll moment
in beam seas is 0.97 of the prediction and the pitch moment 1.02. Without those terms (the
Froude-Krylov-only form the checks had before) this hull's roll would be 1.39 of it (A42 =
-6.6e6 kg m: 1 - g A42 / C44_b = 1.43) and its pitch 1.21 (C35 = 8.8e6 N of a waterplane centred
0.72 m aft).

**The panels.** ~1.4 m panels, 1188 on the hull (at 2.2 rad/s the waves are 12.7 m long: 9 panels
a wavelength, Capytaine's documentation asks for about 8; its own check flags the largest panels,
2.2 m, from 2.0 rad/s), and 240 on the lid: 60 stations along x (uniform),
9 panels a side along the girth (equal arc length), the transom by 12 columns between the
stern section's girth points (conforming); the lid at 5 % of
the draught below the free surface (as the box script's), on every second station, 8 panels across.

**The peer RAO** (`rao`): capytaine.post_pro.rao with the preset's rigid-body mass matrix about the
CO (m, I_g = diag(vessel.inertia) about the CG, r_g = the CG: Fossen 2021 eq. 3.44), the dataset's
hydrostatic stiffness, and the preset's linear damping diag(damping_translational,
damping_rotational) as `dissipation` (osv.toml: Dmtrx.m's diagonal about the CO, which is
Capytaine's rotation centre). The preset's added mass (osv.toml `added_mass`) is not used: A(omega)
is. Stored for heave, roll and pitch at 180 deg (head seas) and 90 deg (beam seas), Capytaine's
convention (amplitudes for e^{-i omega t}, directions of propagation, 0 = towards +x)."""
from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_capytaine_box import G, RHO, THETA, slim  # noqa: E402  (the box script's constants and storage)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")

#: Frequencies (rad/s): 0.2 to 2.2 (at 2.5 the damping rose again: ~1.4 m panels are too coarse there), denser over 0.4-1.2 (the heave, pitch and roll peaks). Not 0.1:
#: there B(omega) is ~1e-2 of its peak and its heave-yaw entry (zero by symmetry) is 2 % of the
#: largest, which the loader's damping-symmetry check refuses; 0.2 still has k sqrt(A_wp) = 0.14.
OMEGAS = np.concatenate([[0.2, 0.3], np.linspace(0.4, 1.2, 11), [1.3, 1.4, 1.55, 1.7, 1.85, 2.0, 2.2]])
#: Directions (deg) of propagation, 0 = towards +x: [0, 180] every 15 (symmetric hull).
DIRECTIONS = np.arange(0.0, 180.1, 15.0)

#: name: main dimensions, the preset's CG (z up from the CO), the vessel's mass and inertia about
#: the CG, the hull parameters (a_f, p_f, a_a, p_a, t, q_aft, q_mid, q_fore) and the preset's
#: targets, the vessel's linear damping about the CO.
HULLS = {
    "osv": dict(
        L=83.0, B=18.0, T=5.0, cg=(-4.5, 0.0, 1.2),
        mass=4976887.5, inertia=(1.97532664875e8, 2.14286112421875e9, 2.14286112421875e9),
        params=(0.6386, 1.0, 0.0, 1.0, 0.6079, 26.7732, 3.6845, 0.7),
        targets=dict(cb=0.65, cw=0.8, lcf=-0.5, lcb=-4.5, gm_t=2.065754437869824, gm_l=120.26121794871794),
        damping=(55768.875, 69768.875, 5052715.642276893, 50369129.37696089, 3632218966.6724005, 3485243096.09375),
        preset="crates/phsplit-core/data/vessels/osv.toml",
        out="python/src/phsplit/scenarios/osv_capytaine.nc", rao_out="python/tests/data/osv_capytaine_rao.nc",
        label="ship-like hull 83 x 18 x 5 m fitted to the MSS osv.m preset"),
}
RES = dict(nx=60, ng=9, transom=12, lid_every=2, lid_ny=8, lid_depth=0.05)


# -- the hull ----------------------------------------------------------------------------------

def waterline(u, p):
    a_f, p_f, a_a, p_a, t = p[:5]
    f = np.ones_like(u, dtype=float)
    w = u > a_f
    f[w] = 1 - ((u[w] - a_f) / (1 - a_f)) ** p_f
    w = u < -a_a
    f[w] = 1 - (1 - t) * ((-u[w] - a_a) / (1 - a_a)) ** p_a
    return np.clip(f, 0.0, 1.0)


def section_exponent(u, p):
    q_a, q_m, q_f = p[5:8]
    return np.where(u >= 0, q_m + (q_f - q_m) * u, q_m + (q_m - q_a) * u)


def analytic_hydrostatics(h, p, n=40001):
    """Displacement, waterplane, centres and GMs of the analytic hull (trapezoidal rule)."""
    L, B, T = h["L"], h["B"], h["T"]
    u = np.linspace(-1, 1, n)
    x = u * L / 2
    f, q = waterline(u, p), section_exponent(u, p)
    integ = lambda y: float(np.trapezoid(y, x))  # noqa: E731
    area = B * T * f * q / (q + 1)
    V = integ(area)
    zb = integ(-T * (0.5 - 1 / (q + 2)) * (q + 1) / q * area) / V
    awp = integ(B * f)
    zg = h["cg"][2]
    return dict(V=V, cb=V / (L * B * T), lcb=integ(x * area) / V, kb=T + zb, awp=awp, cw=awp / (L * B),
                lcf=integ(x * B * f) / awp, gm_t=B ** 3 / 12 * integ(f ** 3) / V + zb - zg,
                gm_l=integ(x ** 2 * B * f) / V + zb - zg)


def fit_parameters(h):
    """The least-squares fit of the docstring on the panelled hull (needs Capytaine for the
    panels' volume and centre of buoyancy; the waterplane integrals are those of the panelled
    waterline polygon). Its result, rounded, is HULLS' `params`."""
    import capytaine as cpt
    from scipy.optimize import least_squares
    tg, L, B = h["targets"], h["L"], h["B"]
    xs = np.linspace(-L / 2, L / 2, RES["nx"] + 1)
    xf = np.linspace(-L / 2, L / 2, 60001)

    def props(p):
        v, fc, _, _ = hull_mesh_arrays(h, p)
        m = cpt.Mesh(v, fc, auto_check=False, auto_clean=False)
        V, zb = m.volume, m.center_of_buoyancy[2]
        yf = np.interp(xf, xs, B / 2 * waterline(2 * xs / L, p))
        awp = np.trapezoid(2 * yf, xf)
        return dict(V=V, lcb=m.center_of_buoyancy[0], awp=awp, lcf=np.trapezoid(2 * yf * xf, xf) / awp,
                    gm_t=np.trapezoid(2 / 3 * yf ** 3, xf) / V + zb - h["cg"][2],
                    gm_l=np.trapezoid(2 * yf * xf ** 2, xf) / V + zb - h["cg"][2])

    def res(p):
        d = props(list(p))
        return [(d["V"] * RHO / h["mass"] - 1) / 5e-4, (d["awp"] / (1.01 * tg["cw"] * L * B) - 1) / 2e-3,
                (d["lcf"] - tg["lcf"]) / 0.3, (d["lcb"] - tg["lcb"]) / 0.5,
                (d["gm_t"] / tg["gm_t"] - 1) / 0.02, (d["gm_l"] / tg["gm_l"] - 1) / 0.02]
    r = least_squares(res, list(h["params"]), bounds=([0, 1, 0, 1, 0.3, 1, 1, 0.7], [0.8, 6, 0.8, 6, 0.95, 30, 30, 30]),
                      diff_step=1e-3)
    return r.x, props(list(r.x))


def _girth_points(yh, T, ng):
    """ng + 1 points (y >= 0, z) down one side of a section y = yh(s), s = -z/T, at equal arc length."""
    s = np.linspace(0.0, 1.0, 801)
    y, z = yh(s), -s * T
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(y), np.diff(z)))])
    target = np.linspace(0.0, arc[-1], ng + 1)
    return np.interp(target, arc, y), np.interp(target, arc, z)


def hull_mesh_arrays(h, p, res=RES):
    """(vertices, faces) of the wetted hull (sides and transom; normals out of the body, into the
    water, as Capytaine's) and of the lid (normal down, as Capytaine's generate_lid)."""
    L, B, T = h["L"], h["B"], h["T"]
    nx, ng = res["nx"], res["ng"]
    xs = np.linspace(-L / 2, L / 2, nx + 1)
    us = 2 * xs / L
    f, q = waterline(us, p), section_exponent(us, p)
    verts, faces = [], []
    # sides: per station, the girth from the port waterline down to the keel and up to starboard
    ring = 2 * ng + 1
    for i in range(nx + 1):
        yy, zz = _girth_points(lambda s: B / 2 * f[i] * (1 - s ** q[i]), T, ng)
        ys = np.concatenate([yy, -yy[-2::-1]])
        zs = np.concatenate([zz, zz[-2::-1]])
        verts += [(xs[i], ys[k], zs[k]) for k in range(ring)]
    for i in range(nx):
        for k in range(ring - 1):
            a, b = i * ring + k, (i + 1) * ring + k
            faces.append([a, b, b + 1, a + 1])
    # the transom at x = -L/2, conforming with the sides: between consecutive girth levels of
    # the stern station, from starboard to port (a gap at this edge spoils the pitch problem)
    nc = res["transom"]
    base = len(verts)
    yy, zz = _girth_points(lambda s: B / 2 * f[0] * (1 - s ** q[0]), T, ng)
    for j in range(ng + 1):
        verts += [(xs[0], e * yy[j], zz[j]) for e in np.linspace(1.0, -1.0, nc + 1)]
    for j in range(ng):
        for c in range(nc):
            a, b = base + j * (nc + 1) + c, base + (j + 1) * (nc + 1) + c
            faces.append([a, b, b + 1, a + 1])
    verts = np.array(verts)
    # the lid
    zl = -res["lid_depth"] * T
    sl = res["lid_depth"]
    lv, lf = [], []
    xl = xs[::res["lid_every"]]
    ul = 2 * xl / L
    fl, ql = waterline(ul, p), section_exponent(ul, p)
    ny = res["lid_ny"]
    for i in range(len(xl)):
        w = B / 2 * fl[i] * (1 - sl ** ql[i])
        lv += [(xl[i], e * w, zl) for e in np.linspace(-1.0, 1.0, ny + 1)]
    for i in range(len(xl) - 1):
        for k in range(ny):
            a, b = i * (ny + 1) + k, (i + 1) * (ny + 1) + k
            lf.append([a, a + 1, b + 1, b])
    return verts, _mirror_consistent(verts, faces), np.array(lv), _mirror_consistent(np.array(lv), lf)


def _mirror_consistent(verts, faces):
    """Each quad's vertex cycle started at a vertex chosen by a rule that mirroring y -> -y
    preserves (the largest x, then |y|, then z), orientation kept. A non-planar quad's centre and
    normal depend on the diagonal its first vertex picks; with the loops' order, port and starboard
    picked different ones, and the hull came out asymmetric at 1e-3 (couplings such as sway-heave
    that symmetry makes zero), enough to merge the fluid-memory fit's groups."""
    out = []
    for fc in faces:
        key = [(round(verts[i][0], 9), round(abs(verts[i][1]), 9), round(verts[i][2], 9)) for i in fc]
        j = max(range(len(fc)), key=lambda n: key[n])
        out.append(list(fc[j:]) + list(fc[:j]))
    return np.array(out)


def rigid_body_mass_matrix(m, inertia, r_g):
    """M_RB about the origin (Fossen 2021 eq. 3.44): [[m I, -m S(r_g)], [m S(r_g), I_g - m S(r_g)^2]]."""
    r = np.asarray(r_g, dtype=float)
    S = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    M = np.zeros((6, 6))
    M[:3, :3] = m * np.eye(3)
    M[:3, 3:] = -m * S
    M[3:, :3] = m * S
    M[3:, 3:] = np.diag(inertia) - m * S @ S
    return M


# -- Capytaine ---------------------------------------------------------------------------------

def build_body(cpt, name, h):
    """The floating body, with q_mid adjusted so that rho V = the vessel's mass within 1e-4."""
    p = list(h["params"])
    target = h["mass"] / RHO

    def scaled(c):
        return p[:5] + [c * v for v in p[5:8]]

    def mesh_volume(c):
        v, fc, _, _ = hull_mesh_arrays(h, scaled(c))
        return cpt.Mesh(v, fc, auto_check=False).volume
    lo, hi = 0.8, 1.25
    for _ in range(60):  # bisection: the volume grows with the section exponents
        mid = 0.5 * (lo + hi)
        if mesh_volume(mid) < target:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-8:
            break
    p = scaled(0.5 * (lo + hi))
    v, fc, lv, lf = hull_mesh_arrays(h, p)
    hull = cpt.Mesh(v, fc, name=name)
    lid = cpt.Mesh(lv, lf, name=f"lid of {name}")
    body = cpt.FloatingBody(mesh=hull, lid_mesh=lid, dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                            center_of_mass=h["cg"], name=name)
    return body, hull, lid, p


def dof_matrix(xr, M, dofs):
    return xr.DataArray(np.asarray(M, dtype=float), dims=("influenced_dof", "radiating_dof"),
                        coords={"influenced_dof": list(dofs), "radiating_dof": list(dofs)})


def main(name: str = "osv") -> None:
    import capytaine as cpt
    import xarray as xr
    from capytaine.post_pro.mean_drift_force import far_field_mean_drift_force

    h = HULLS[name]
    t0 = time.time()
    body, hull, lid, p = build_body(cpt, name, h)
    hs = body.compute_hydrostatics(rho=RHO, g=G)
    M = rigid_body_mass_matrix(h["mass"], h["inertia"], h["cg"])
    dofs = list(body.dofs)
    body.inertia_matrix = dof_matrix(xr, M, dofs)
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
    C = body.hydrostatic_stiffness.values
    V = float(hs["disp_volume"])
    awp = float(hs["waterplane_area"])
    cob = np.asarray(hs["center_of_buoyancy"], dtype=float)
    wp_c = np.asarray(hs.get("waterplane_center", [np.nan, np.nan, 0.0]), dtype=float)
    mg = h["mass"] * G
    tg = h["targets"]
    summary = {
        "displacement_m3": V, "displacement_preset_m3": h["mass"] / RHO,
        "waterplane_area_m2": awp, "waterplane_area_preset_m2": tg["cw"] * h["L"] * h["B"],
        "gm_t_m": C[3, 3] / mg, "gm_t_preset_m": tg["gm_t"], "gm_l_m": C[4, 4] / mg, "gm_l_preset_m": tg["gm_l"],
        "lcb_m": cob[0], "kb_m": h["T"] + cob[2], "lcf_m": wp_c[0],
    }
    print(f"{name}: {hull.nb_faces} hull + {lid.nb_faces} lid panels, q_mid = {p[6]:.5f}")
    for k, v in summary.items():
        print(f"  {k:28s} {v:.6g}")
    print(f"  analytic: {analytic_hydrostatics(h, p)}")

    coords = {"omega": OMEGAS, "wave_direction": np.radians(DIRECTIONS), "radiating_dof": dofs,
              "water_depth": [np.inf], "rho": [RHO], "g": [G], "theta": THETA}
    solver = cpt.BEMSolver()
    ds = solver.fill_dataset(xr.Dataset(coords=coords), body, progress_bar=False)
    t1 = time.time()
    # the far-field mean drift of the free-floating body (as the box script)
    drift = far_field_mean_drift_force(cpt.post_pro.rao(ds), ds)
    nd = ds.sizes["wave_direction"]
    ds["drift_force"] = xr.DataArray(
        np.stack([np.stack([np.real(drift[f"drift_force_{n}"].isel(wave_direction_k=k, wave_direction_l=k).values)
                            for n in ("surge", "sway", "yaw")], axis=-1) for k in range(nd)], axis=1),
        dims=("omega", "wave_direction", "drift_dof"), coords={"drift_dof": ["Surge", "Sway", "Yaw"]},
        attrs={"long_name": "mean drift force and moment per square metre of wave amplitude (far field, "
                            "capytaine.post_pro.mean_drift_force.far_field_mean_drift_force of the free-floating "
                            "body, no damping but the radiation's; phsplit's addition)",
               "units": "N/m^2 (surge, sway), N m/m^2 (yaw)"})
    inf = solver.fill_dataset(xr.Dataset(coords={"omega": [np.inf], "radiating_dof": dofs,
                                                 "water_depth": [np.inf], "rho": [RHO], "g": [G]}),
                              body, progress_bar=False)
    ds["added_mass_infinite_frequency"] = inf["added_mass"].isel(omega=0, drop=True).reset_coords(drop=True)
    ds["added_mass_infinite_frequency"].attrs = {"long_name": "added mass at infinite frequency (Capytaine, omega = inf)"}
    ds["waterplane_area"] = xr.DataArray(awp, attrs={"units": "m^2"})
    ds["disp_volume"] = xr.DataArray(V, attrs={"units": "m^3"})
    t2 = time.time()

    # the peer RAO, before the dataset is reduced
    D = np.diag(h["damping"])
    rao = cpt.post_pro.rao(ds, dissipation=dof_matrix(xr, D, dofs))
    write_rao(cpt, xr, ds, rao, h, M, D, name)

    ds = slim(cpt, ds)
    cg = h["cg"]
    ds.attrs.update({
        "phsplit_note": f"{h['label']}; made by scripts/gen_capytaine_hulls.py (its docstring: the hull and its sources)",
        "capytaine_version": cpt.__version__,
        "preset": h["preset"],
        "mesh": (f"parametric hull y = B/2 f(2x/L) (1 - s^q(2x/L)), s = -z/T, L {h['L']:g} B {h['B']:g} T {h['T']:g} m; "
                 f"(a_f, p_f, a_a, p_a, t, q_aft, q_mid, q_fore) = ({', '.join(f'{v:.6g}' for v in p)}): "
                 f"{hull.nb_faces} hull panels (sides and transom, no deck)"),
        "lid": f"at z = {-RES['lid_depth'] * h['T']:g} m: {lid.nb_faces} panels (against irregular frequencies)",
        "hydrostatics": "; ".join(f"{k} {v:.6g}" for k, v in summary.items()),
        "inertia_matrix": "the preset's rigid-body mass matrix about the rotation centre (mass, inertia about the CG, CG offset)",
        "rho": RHO, "g": G, "water_depth": "inf",
        "rotation_center": "0 0 0",
        "center_of_mass": f"{cg[0]:.6g} {cg[1]:.6g} {cg[2]:.6g}",
        "frame": "x forward, y to port, z up; origin at the waterline, midships (MSS's CO); directions: propagation, 0 = towards +x",
    })
    for k, v in list(ds.attrs.items()):
        if not isinstance(v, (str, int, float)):
            ds.attrs[k] = str(v)
    out = os.path.join(ROOT, h["out"])
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}: {dict(ds.sizes)}; {os.path.getsize(out)} bytes; "
          f"BEM {t1 - t0:.0f} s, drift and A(inf) {t2 - t1:.0f} s")


def write_rao(cpt, xr, ds, rao, h, M, D, name):
    """Heave, roll and pitch RAO at 180 and 90 deg (Capytaine's convention) with its inputs."""
    sel = rao.sel(wave_direction=np.radians([180.0, 90.0]), method="nearest")
    sel = sel.sel(radiating_dof=["Heave", "Roll", "Pitch"])
    out = xr.Dataset(
        {"rao_real": (("wave_direction", "omega", "dof"), np.real(sel.transpose("wave_direction", "omega", "radiating_dof").values)),
         "rao_imag": (("wave_direction", "omega", "dof"), np.imag(sel.transpose("wave_direction", "omega", "radiating_dof").values)),
         "mass_matrix": (("i", "j"), M), "damping_matrix": (("i", "j"), D),
         "stiffness_matrix": (("i", "j"), np.asarray(ds["hydrostatic_stiffness"].values, dtype=float))},
        coords={"wave_direction_deg": ("wave_direction", [180.0, 90.0]), "omega": ds["omega"].values,
                "dof": ["Heave", "Roll", "Pitch"], "i": list(ds["radiating_dof"].values), "j": list(ds["radiating_dof"].values)})
    out["rao_real"].attrs = {"units": "m/m (heave), rad/m (roll, pitch)"}
    out["rao_imag"].attrs = {"units": "m/m (heave), rad/m (roll, pitch)"}
    out.attrs.update({
        "phsplit_note": (f"peer reference: capytaine.post_pro.rao of {h['out']} for the {name} preset "
                         f"({h['preset']}); made by scripts/gen_capytaine_hulls.py"),
        "capytaine_version": cpt.__version__,
        "equation": "RAO = [-omega^2 (M + A(omega)) - i omega (B(omega) + D) + C]^-1 F(omega), F = Froude-Krylov + diffraction",
        "convention": "Capytaine's: complex amplitudes for the time dependence exp(-i omega t) per metre of wave amplitude "
                      "(the wave elevation at the origin eta = Re(exp(-i omega t))); wave_direction: propagation, "
                      "0 = towards +x, 180 = head seas, 90 = beam seas from starboard (towards +y, port)",
        "reference_point": "the rotation centre (0, 0, 0): the waterline at midships (MSS's CO, the preset's body origin); "
                           "roll and pitch are rotations about axes through it, heave the vertical motion of it",
        "mass": "M: the preset's rigid-body mass matrix about the rotation centre, Fossen 2021 eq. 3.44: "
                "[[m I, -m S(r_g)], [m S(r_g), I_g - m S(r_g)^2]], m = 4976887.5 kg, I_g = diag(vessel.inertia) about the CG, "
                "r_g = (-4.5, 0, 1.2) m; the preset's added_mass is NOT used, A(omega) of the dataset is",
        "stiffness": "C: the dataset's hydrostatic_stiffness (Capytaine, about the rotation centre, with the CG above; mass rho V)",
        "damping": "D: the preset's linear damping diag(damping_translational, damping_rotational) of osv.toml "
                   "(about the CO = the rotation centre), passed as dissipation; plus the radiation damping B(omega)",
    })
    path = os.path.join(ROOT, h["rao_out"])
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    out.to_netcdf(path)
    print(f"wrote {path}: {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--fit":
        print(fit_parameters(HULLS[sys.argv[2] if len(sys.argv) > 2 else "osv"]))
    else:
        for n in (sys.argv[1:] or list(HULLS)):
            main(n)
