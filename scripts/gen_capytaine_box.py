"""Compute the hydrodynamic data of a small box barge with Capytaine (the open-source BEM
solver) and store it as the test dataset python/tests/data/box_barge_capytaine.nc.

The mesh is deliberately coarse (seconds on a laptop); the numbers are Capytaine's, not a
converged hydrodynamic study. Run: `make capytaine-box` (which installs capytaine into a separate
virtual environment, .venv-capytaine: it is not a dependency of phsplit).

Two hulls (see HULLS): the test barge (20 x 8 x 2 m; 0.3-2.0 rad/s, 10 values; directions 0, 90,
180 degrees) and the box with the paper vessel's main dimensions, for the shipped scenario
dp-weather (python/src/phsplit/scenarios/paper_box_capytaine.nc). Six rigid-body DOFs about the
waterline centre, infinite water depth; directions are the waves' propagation (0: towards +x).
"""
from __future__ import annotations

import os
import sys

import numpy as np


#: The hulls: (length, beam, draft, panels along each, frequencies, directions in degrees, name).
#: "box_barge": the small test barge. "paper_box": a box with the paper's vessel's displacement
#: (6.3622085e6 kg / 1025 kg/m^3 = 6207 m^3), waterplane area (1383.4 m^2) and metacentric heights
#: (GM_T 2.144 m, GM_L 103.6 m): with BM = B^2/(12 T), L^2/(12 T) and a common BG, these give
#: L = 76.2 m, B = 18.2 m, T = 4.49 m (docs/model.md 5.9) -- the length of the supply vessel of
#: Fossen, Sagatun & Sorensen (1996).
HULLS = {
    "box_barge": ((20.0, 8.0, 2.0), (30, 12, 6), np.linspace(0.3, 2.0, 10), [0.0, 90.0, 180.0],
                  "box barge 20 x 8 x 2 m"),
    "paper_box": ((76.2, 18.2, 4.49), (38, 10, 3), np.linspace(0.2, 2.0, 16), [0.0, 45.0, 90.0, 135.0, 180.0],
                  "box 76.2 x 18.2 x 4.49 m with the paper vessel's displacement, waterplane area and GMs"),
}
# (A 10 x 4 x 2 panel mesh of the barge gave mean drift forces of the wrong sign at most
# frequencies; at 30 x 12 x 6 they are physical: along the waves, and in head seas at 2 rad/s
# 4.25e4 N/m^2, near the wall limit rho g B / 2 = 4.02e4 N/m^2.)


#: Directions of the Kochin functions for the far-field drift: beyond [0, 2π] on both sides.
THETA = np.linspace(-np.pi / 6, 2 * np.pi + np.pi / 6, 121)


def main(out: str, hull: str = "box_barge") -> None:
    import capytaine as cpt

    (length, beam, draft), res, omegas, dirs, label = HULLS[hull]
    from capytaine.post_pro.mean_drift_force import far_field_mean_drift_force

    mesh = cpt.mesh_parallelepiped(size=(length, beam, draft), resolution=res, center=(0.0, 0.0, -draft / 2))
    hull = mesh.immersed_part()
    body = cpt.FloatingBody(mesh=hull, dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                            center_of_mass=(0.0, 0.0, 0.0), name="box")
    body.inertia_matrix = body.compute_rigid_body_inertia()
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness()
    import xarray as xr

    test_matrix = xr.Dataset(coords={
        "omega": omegas,
        "wave_direction": np.radians(dirs),
        "radiating_dof": list(body.dofs),
        "water_depth": [np.inf],
        "rho": [1025.0],
        "theta": THETA,
    })
    ds = cpt.BEMSolver().fill_dataset(test_matrix, body)
    # Mean drift (far field, Maruo) of the free-floating body in regular waves, per square metre of
    # amplitude: the diagonal (k = l) of Capytaine's bichromatic table. DP does not act at wave
    # frequencies, so the free-floating motions are the ones to use.
    drift = far_field_mean_drift_force(cpt.post_pro.rao(ds), ds)
    nd = ds.sizes["wave_direction"]
    ds["drift_force"] = xr.DataArray(
        np.stack([np.stack([np.real(drift[f"drift_force_{n}"].isel(wave_direction_k=k, wave_direction_l=k).values)
                            for n in ("surge", "sway", "yaw")], axis=-1) for k in range(nd)], axis=1),
        dims=("omega", "wave_direction", "drift_dof"),
        coords={"drift_dof": ["Surge", "Sway", "Yaw"]},
        attrs={"long_name": "mean drift force and moment per square metre of wave amplitude (far field, "
                            "capytaine.post_pro.mean_drift_force.far_field_mean_drift_force; phsplit's addition)",
               "units": "N/m^2 (surge, sway), N m/m^2 (yaw)"})
    ds = ds.drop_vars([v for v in ("kochin_diffraction", "kochin_radiation") if v in ds], errors="ignore")
    ds = ds.drop_dims("theta", errors="ignore")
    ds = cpt.io.xarray.separate_complex_values(ds)
    # Plain string labels for the DOF coordinates (Capytaine keeps them categorical in memory).
    for name in list(ds.coords):
        if str(ds[name].dtype) == "category" or "Categorical" in type(ds[name].dtype).__name__:
            ds = ds.assign_coords({name: [str(v) for v in ds[name].values]})
    ds.attrs["phsplit_note"] = (f"{label}, coarse mesh ({res} panels), made by scripts/gen_capytaine_box.py; "
                                f"Capytaine {cpt.__version__}")
    for k, v in list(ds.attrs.items()):
        if not isinstance(v, (str, int, float)):
            ds.attrs[k] = str(v)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}: {dict(ds.sizes)}; variables {sorted(ds.data_vars)}")


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    if len(sys.argv) > 1:
        main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "box_barge")
    else:
        main(os.path.join(here, "..", "python", "tests", "data", "box_barge_capytaine.nc"), "box_barge")
        main(os.path.join(here, "..", "python", "src", "phsplit", "scenarios", "paper_box_capytaine.nc"), "paper_box")
