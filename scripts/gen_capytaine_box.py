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
    "box_barge": ((20.0, 8.0, 2.0), (10, 4, 2), np.linspace(0.3, 2.0, 10), [0.0, 90.0, 180.0],
                  "box barge 20 x 8 x 2 m"),
    "paper_box": ((76.2, 18.2, 4.49), (16, 4, 2), np.linspace(0.2, 2.0, 16), [0.0, 45.0, 90.0, 135.0, 180.0],
                  "box 76.2 x 18.2 x 4.49 m with the paper vessel's displacement, waterplane area and GMs"),
}


def main(out: str, hull: str = "box_barge") -> None:
    import capytaine as cpt

    (length, beam, draft), res, omegas, dirs, label = HULLS[hull]
    mesh = cpt.mesh_parallelepiped(size=(length, beam, draft), resolution=res, center=(0.0, 0.0, -draft / 2))
    hull = mesh.immersed_part()
    body = cpt.FloatingBody(mesh=hull, dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                            center_of_mass=(0.0, 0.0, 0.0), name="box_barge")
    test_matrix = cpt.xr.Dataset(coords={
        "omega": omegas,
        "wave_direction": np.radians(dirs),
        "radiating_dof": list(body.dofs),
        "water_depth": [np.inf],
        "rho": [1025.0],
    }) if hasattr(cpt, "xr") else None
    import xarray as xr

    if test_matrix is None:
        test_matrix = xr.Dataset(coords={
            "omega": omegas,
            "wave_direction": np.radians(dirs),
            "radiating_dof": list(body.dofs),
            "water_depth": [np.inf],
            "rho": [1025.0],
        })
    ds = cpt.BEMSolver().fill_dataset(test_matrix, body)
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
