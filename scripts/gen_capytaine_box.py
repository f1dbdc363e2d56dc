"""Compute the hydrodynamic data of two box hulls with Capytaine (the open-source BEM solver) and
store them as NetCDF: the test barge (python/tests/data/box_barge_capytaine.nc, and a small
companion computed about the centre of gravity, box_barge_capytaine_cg.nc, that tests the
loader's change of reference point) and the box with the paper vessel's main dimensions for the
shipped scenario dp-weather (python/src/phsplit/scenarios/paper_box_capytaine.nc).

Run: `make capytaine-box` (it installs Capytaine into its own virtual environment,
.venv-capytaine: Capytaine is not a dependency of phsplit). About a minute on one core.

What is computed (docs/hydrodynamic-data.md):
- the wetted hull only: `mesh_parallelepiped(..., missing_sides={"top"})`, so no panels lie in the
  free surface (a closed box keeps its deck at z = 0, and those panels spoil every result);
- an interior lid a little below the free surface (`generate_lid`), which removes the irregular
  frequencies of the boundary-integral equation (Capytaine's documentation, "Irregular
  frequencies");
- rho = 1025 kg/m^3 and g = 9.81 m/s^2 for everything, the inertia matrix and the hydrostatics
  included; infinite water depth; six rigid-body DOFs about the rotation centre stored in the
  file (the waterline centre), with the centre of mass stored as well;
- added mass and radiation damping over the frequencies, the added mass at infinite frequency
  (`added_mass_infinite_frequency`), the excitation force and its Froude-Krylov part, the
  hydrostatics (stiffness, waterplane area, displaced volume, centre of buoyancy), and the
  far-field mean drift (phsplit's `drift_force` variable).
Directions are the waves' propagation (0: towards +x), over [0, 180] degrees: the hulls are
symmetric port-starboard, and the loader mirrors the rest (symmetric = true)."""
from __future__ import annotations

import os
import sys

import numpy as np

RHO, G = 1025.0, 9.81


def paper_box_dimensions():
    """A box with the paper vessel's displacement (6.3622085e6 kg / 1025 kg/m^3 = 6207 m^3),
    waterplane area (1383.4 m^2) and metacentric heights (GM_T 2.144 m, GM_L 103.6 m): with
    BM = B^2/(12 T), L^2/(12 T) and a common BG, L = 76.2 m, B = 18.2 m, T = 4.49 m (docs/model.md
    5.9) -- the length of the supply vessel of Fossen, Sagatun & Sorensen (1996). Its centre of
    gravity follows from GM_T: KG = KB + BM_T - GM_T = T/2 + B^2/(12 T) - GM_T, i.e. 1.759 m
    above the waterline."""
    length, beam, draft = 76.2, 18.2, 4.49
    kg = draft / 2 + beam ** 2 / (12 * draft) - 2.144
    return (length, beam, draft), kg - draft


#: The hulls: (length, beam, draft), centre of gravity above the waterline (m), panels along x,
#: y, z, frequencies (rad/s), directions (degrees), drift on/off, description.
_PB, _PB_ZG = paper_box_dimensions()
HULLS = {
    # a 20 x 8 x 2 m barge with its centre of gravity 0.5 m above the waterline (KG 2.5 m,
    # GM_T = 1 + 64/24 - 2.5 = 1.17 m): ~1 m panels
    "box_barge": ((20.0, 8.0, 2.0), 0.5, (20, 8, 2), np.linspace(0.3, 2.0, 10), np.arange(0.0, 180.1, 22.5), True,
                  "box barge 20 x 8 x 2 m, centre of gravity 0.5 m above the waterline"),
    # the same barge about its centre of gravity, three of its frequencies and directions, no drift:
    # the reference of the loader's change of reference point
    "box_barge_cg": ((20.0, 8.0, 2.0), 0.5, (20, 8, 2), np.linspace(0.3, 2.0, 10)[[0, 4, 9]], np.array([0.0, 45.0, 90.0]), False,
                     "box barge 20 x 8 x 2 m computed about its centre of gravity"),
    # ~1.9 m panels (at 2 rad/s, 15.4 m waves: 8 panels a wavelength, Capytaine's own criterion)
    "paper_box": (_PB, _PB_ZG, (40, 10, 3), np.linspace(0.2, 2.0, 16), np.arange(0.0, 180.1, 11.25), True,
                  "box 76.2 x 18.2 x 4.49 m with the paper vessel's displacement, waterplane area and GMs"),
}

#: Directions of the Kochin functions for the far-field drift: beyond [0, 2 pi] on both sides.
THETA = np.linspace(-np.pi / 6, 2 * np.pi + np.pi / 6, 121)


def slim(cpt, ds):
    """The dataset as stored: only what phsplit reads or checks (the diffraction part is
    excitation - Froude-Krylov), complex values as real and imaginary parts, and plain string
    labels for the DOF coordinates (Capytaine keeps them categorical in memory)."""
    ds = ds.drop_vars([v for v in ("kochin_diffraction", "kochin_radiation", "kochin", "diffraction_force")
                       if v in ds.variables], errors="ignore")
    ds = ds.drop_dims("theta", errors="ignore")
    for c in ("freq", "period", "wavelength"):
        if c in ds.coords:
            ds = ds.drop_vars(c)
    ds = cpt.io.xarray.separate_complex_values(ds)
    for c in list(ds.coords):
        if str(ds[c].dtype) == "category" or "Categorical" in type(ds[c].dtype).__name__:
            ds = ds.assign_coords({c: [str(v) for v in ds[c].values]})
    return ds


def main(out: str, name: str) -> None:
    import capytaine as cpt
    import xarray as xr
    from capytaine.post_pro.mean_drift_force import far_field_mean_drift_force

    (length, beam, draft), zg, res, omegas, dirs, with_drift, label = HULLS[name]
    hull = cpt.mesh_parallelepiped(size=(length, beam, draft), resolution=res, center=(0.0, 0.0, -draft / 2),
                                   missing_sides={"top"}, name=name)
    # The lid: the whole interior waterplane, 5 % of the draft below the free surface, panelled
    # as the bottom. (At 1 % of the draft, a tenth of a panel's size, the paper box's heave and
    # pitch damping came out negative at 1.88 and 2.0 rad/s; at 5 % and 10 % they agree within
    # 3 %, and with a mesh without lid within the mesh's own convergence. Capytaine's generate_lid finds no lid on some of these box
    # meshes, depending on where its candidate grid falls, so the rectangle is built directly;
    # mesh_rectangle's size is (along y, along x)).
    lid_z = -0.05 * draft
    lid = cpt.mesh_rectangle(size=(beam, length), center=(0.0, 0.0, lid_z), resolution=(res[1], res[0]),
                             normal=(0.0, 0.0, -1.0), name=f"lid of {name}")
    rotation_center = (0.0, 0.0, zg) if name.endswith("_cg") else (0.0, 0.0, 0.0)
    body = cpt.FloatingBody(mesh=hull, lid_mesh=lid, dofs=cpt.rigid_body_dofs(rotation_center=rotation_center),
                            center_of_mass=(0.0, 0.0, zg), name=name)
    hs = body.compute_hydrostatics(rho=RHO, g=G)
    body.inertia_matrix = body.compute_rigid_body_inertia(rho=RHO)
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)

    coords = {"omega": omegas, "wave_direction": np.radians(dirs), "radiating_dof": list(body.dofs),
              "water_depth": [np.inf], "rho": [RHO], "g": [G]}
    if with_drift:
        coords["theta"] = THETA
    solver = cpt.BEMSolver()
    ds = solver.fill_dataset(xr.Dataset(coords=coords), body, progress_bar=False)
    if with_drift:
        # Mean drift (far field, Maruo) of the free-floating body in regular waves, per square
        # metre of amplitude: the diagonal (k = l) of Capytaine's bichromatic table. DP does not
        # act at wave frequencies, so the free-floating motions are the ones to use.
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
    # The added mass at infinite frequency (radiation problems at omega = inf; no diffraction).
    inf = solver.fill_dataset(xr.Dataset(coords={"omega": [np.inf], "radiating_dof": list(body.dofs),
                                                 "water_depth": [np.inf], "rho": [RHO], "g": [G]}),
                              body, progress_bar=False)
    ds["added_mass_infinite_frequency"] = inf["added_mass"].isel(omega=0, drop=True).reset_coords(drop=True)
    ds["added_mass_infinite_frequency"].attrs = {"long_name": "added mass at infinite frequency (Capytaine, omega = inf)"}
    ds["waterplane_area"] = xr.DataArray(float(hs["waterplane_area"]), attrs={"units": "m^2"})
    ds["disp_volume"] = xr.DataArray(float(hs["disp_volume"]), attrs={"units": "m^3"})
    ds = slim(cpt, ds)
    rc = np.asarray(rotation_center, dtype=float)
    ds.attrs.update({
        "phsplit_note": f"{label}; made by scripts/gen_capytaine_box.py",
        "capytaine_version": cpt.__version__,
        "mesh": f"mesh_parallelepiped(size=({length}, {beam}, {draft}), resolution={res}, missing_sides={{'top'}}): "
                f"{hull.nb_faces} hull panels",
        "lid": f"mesh_rectangle at z = {lid_z:g} m: {lid.nb_faces} panels (against irregular frequencies)",
        "rho": RHO, "g": G, "water_depth": "inf",
        "rotation_center": f"{rc[0]:.6g} {rc[1]:.6g} {rc[2]:.6g}",
        "center_of_mass": f"0 0 {zg:.6g}",
        "frame": "x forward, y to port, z up; origin at the waterline centre; directions: propagation, 0 = towards +x",
    })
    for k, v in list(ds.attrs.items()):
        if not isinstance(v, (str, int, float)):
            ds.attrs[k] = str(v)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}: {dict(ds.sizes)}; {hull.nb_faces} hull + {lid.nb_faces} lid panels; "
          f"{os.path.getsize(out)} bytes")


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    tests = os.path.join(here, "..", "python", "tests", "data")
    if len(sys.argv) > 1:
        main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "box_barge")
    else:
        main(os.path.join(tests, "box_barge_capytaine.nc"), "box_barge")
        main(os.path.join(tests, "box_barge_capytaine_cg.nc"), "box_barge_cg")
        main(os.path.join(here, "..", "python", "src", "phsplit", "scenarios", "paper_box_capytaine.nc"), "paper_box")
