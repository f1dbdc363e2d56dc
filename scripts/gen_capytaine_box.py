"""Compute the hydrodynamic data of a small box barge with Capytaine (the open-source BEM
solver) and store it as the test dataset python/tests/data/box_barge_capytaine.nc.

The mesh is deliberately coarse (seconds on a laptop); the numbers are Capytaine's, not a
converged hydrodynamic study. Run: `make capytaine-box` (which installs capytaine into a separate
virtual environment, .venv-capytaine: it is not a dependency of phsplit).

Box barge: 20 m long, 8 m wide, 2 m draft, floating freely; six rigid-body DOFs about its
centre of gravity at the waterline centre. Frequencies 0.3-2.0 rad/s (10 values), wave
directions 0, 90 and 180 degrees (propagation towards +x, +y, -x). Infinite water depth.
"""
from __future__ import annotations

import os
import sys

import numpy as np


def main(out: str) -> None:
    import capytaine as cpt

    mesh = cpt.mesh_parallelepiped(size=(20.0, 8.0, 2.0), resolution=(10, 4, 2), center=(0.0, 0.0, -1.0))
    hull = mesh.immersed_part()
    body = cpt.FloatingBody(mesh=hull, dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                            center_of_mass=(0.0, 0.0, 0.0), name="box_barge")
    test_matrix = cpt.xr.Dataset(coords={
        "omega": np.linspace(0.3, 2.0, 10),
        "wave_direction": np.radians([0.0, 90.0, 180.0]),
        "radiating_dof": list(body.dofs),
        "water_depth": [np.inf],
        "rho": [1025.0],
    }) if hasattr(cpt, "xr") else None
    import xarray as xr

    if test_matrix is None:
        test_matrix = xr.Dataset(coords={
            "omega": np.linspace(0.3, 2.0, 10),
            "wave_direction": np.radians([0.0, 90.0, 180.0]),
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
    ds.attrs["phsplit_note"] = ("box barge 20 x 8 x 2 m, coarse mesh (10 x 4 x 2 panels per face), made by "
                                "scripts/gen_capytaine_box.py for the tests; Capytaine " + cpt.__version__)
    for k, v in list(ds.attrs.items()):
        if not isinstance(v, (str, int, float)):
            ds.attrs[k] = str(v)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}: {dict(ds.sizes)}; variables {sorted(ds.data_vars)}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "python", "tests",
                                                              "data", "box_barge_capytaine.nc"))
