"""Hydrodynamic data from Capytaine (the open-source BEM solver, https://capytaine.org): a
loader from Capytaine's xarray dataset to phsplit's tables (docs/model.md §5.9).

:func:`from_capytaine` takes the dataset that ``capytaine.BEMSolver().fill_dataset`` returns (or
that file written with ``capytaine.io.xarray.separate_complex_values`` and reopened) and gives:

* ``added_mass``: the 6×6 added-mass matrix at the highest computed frequency (the nearest to the
  infinite-frequency value a coarse table has), or at a chosen ``omega``;
* the ``[waves]`` table's transfer-function keys: ``rao_frequencies`` (rad/s),
  ``rao_directions`` (degrees), ``force_rao_real`` and ``force_rao_imag`` (``[direction]
  [frequency][dof]``): the excitation force (Froude–Krylov plus diffraction) per metre of wave
  amplitude. Capytaine writes amplitudes for the time dependence ``e^{−iωt}``, phsplit for
  ``e^{+iωt}``: the loader takes the complex conjugate, which describes the same real force.

* ``drift_coefficients`` (``[direction][frequency][3]``: surge, sway, yaw), when the dataset has
  the variable ``drift_force`` (``omega``, ``wave_direction``, ``drift_dof``) that
  ``scripts/gen_capytaine_box.py`` adds from Capytaine's far-field mean drift
  (``capytaine.post_pro.mean_drift_force.far_field_mean_drift_force`` on the free-floating
  motions; it needs Kochin functions, i.e. a ``theta`` coordinate in the test matrix). It is
  real (a mean force): no conjugation.

The added mass needs a general mass matrix, which the paper's vessel model does not have yet
(issue 18): it is returned, not applied."""
from __future__ import annotations

import numpy as np

from . import _core

DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")


def _complex(ds, name):
    v = ds[name]
    if "complex" in v.dims:
        return v.sel(complex="re") + 1j * v.sel(complex="im")
    return v


def from_capytaine(ds, omega: float | None = None, symmetric: bool = False) -> dict:
    """phsplit's tables from a Capytaine dataset (an ``xarray.Dataset`` or a path to its NetCDF
    file). ``symmetric=True`` mirrors directions in (0, 180) degrees to (180, 360) for a hull
    symmetric about its x–z plane (sway, roll and yaw change sign)."""
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        try:
            ds = xr.open_dataset(ds)
        except (OSError, ValueError) as e:
            raise _core.InvalidInputError(f"cannot read the Capytaine dataset {ds!r}: {e}") from None
    need = ["added_mass", "omega", "wave_direction", "influenced_dof", "radiating_dof"]
    missing = [n for n in need if n not in ds.variables]
    has_exc = "excitation_force" in ds.variables or {"Froude_Krylov_force", "diffraction_force"} <= set(ds.variables)
    if not has_exc:
        missing.append("excitation_force (or Froude_Krylov_force and diffraction_force)")
    if missing:
        raise _core.InvalidInputError(
            f"the Capytaine dataset lacks {', '.join(missing)}: compute it with capytaine.BEMSolver().fill_dataset "
            f"over omega, wave_direction and the six rigid-body DOFs")
    dofs = [str(d) for d in ds["influenced_dof"].values]
    if [d for d in DOFS if d not in dofs]:
        raise _core.InvalidInputError(f"the Capytaine dataset's influenced_dof must hold {', '.join(DOFS)}, got {dofs}")
    exc = _complex(ds, "excitation_force") if "excitation_force" in ds.variables else \
        _complex(ds, "Froude_Krylov_force") + _complex(ds, "diffraction_force")
    exc = exc.sel(influenced_dof=list(DOFS)).transpose("wave_direction", "omega", "influenced_dof")
    w = np.asarray(ds["omega"].values, dtype=float)
    if omega is None:
        a = ds["added_mass"].isel(omega=int(np.argmax(w)))
    else:
        if not (isinstance(omega, (int, float)) and float(w.min()) <= float(omega) <= float(w.max())):
            raise _core.InvalidInputError(f"omega must lie within the dataset's frequencies "
                                          f"[{w.min():g}, {w.max():g}] rad/s, got {omega!r}")
        a = ds["added_mass"].interp(omega=float(omega))
    added = np.asarray(a.sel(influenced_dof=list(DOFS), radiating_dof=list(DOFS)).values, dtype=float)
    f = np.conj(np.asarray(exc.values))  # e^{-iωt} -> e^{+iωt}
    dirs = np.degrees(np.asarray(ds["wave_direction"].values, dtype=float))
    order = np.argsort(w)
    w, f = w[order], f[:, order, :]
    if symmetric:
        sign = np.array([1, -1, 1, -1, 1, -1])
        extra = [(360.0 - d, f[i] * sign) for i, d in enumerate(dirs) if 0.0 < d < 180.0]
        dirs = np.concatenate([dirs, [d for d, _ in extra]])
        f = np.concatenate([f, np.array([x for _, x in extra]).reshape(-1, *f.shape[1:])])
    d_order = np.argsort(dirs)
    dirs, f = dirs[d_order], f[d_order]
    waves = {"rao_frequencies": w.tolist(), "rao_directions": dirs.tolist(),
             "force_rao_real": f.real.tolist(), "force_rao_imag": f.imag.tolist()}
    if "drift_force" in ds.variables:
        dv = ds["drift_force"]
        if set(dv.dims) != {"omega", "wave_direction", "drift_dof"}:
            raise _core.InvalidInputError(f"the dataset's drift_force must have the dimensions omega, wave_direction "
                                          f"and drift_dof, got {dv.dims}")
        dr = np.asarray(dv.sel(drift_dof=["Surge", "Sway", "Yaw"]).transpose("wave_direction", "omega", "drift_dof")
                        .values, dtype=float)[:, order, :]
        if symmetric:
            base = np.degrees(np.asarray(ds["wave_direction"].values, dtype=float))
            extra = [dr[i] * np.array([1, -1, -1]) for i, d in enumerate(base) if 0.0 < d < 180.0]
            dr = np.concatenate([dr, np.array(extra).reshape(-1, *dr.shape[1:])])
        waves["drift_coefficients"] = dr[d_order].tolist()
    return {"added_mass": added, "waves": waves}
