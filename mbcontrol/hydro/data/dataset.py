"""The body-frame hydro dataset every source produces (BEM runs, WAMIT, BEMIO, Capytaine files):
its variables' units and its matrix layout, X[..., i_force, j_motion] (influenced, radiating)."""
from __future__ import annotations

import numpy as np
import xarray as xr

BODY_FRAME_UNITS = {
    "added_mass": "kg, kg m, kg m^2 (translation/rotation DOF pairs)",
    "added_mass_inf": "kg, kg m, kg m^2 (translation/rotation DOF pairs)",
    "added_mass_zero": "kg, kg m, kg m^2 (translation/rotation DOF pairs)",
    "radiation_damping": "kg/s, kg m/s, kg m^2/s (translation/rotation DOF pairs)",
    "excitation_force": "N/m, N m/m (per m of wave amplitude)",
    "froude_krylov_force": "N/m, N m/m (per m of wave amplitude)",
    "diffraction_force": "N/m, N m/m (per m of wave amplitude)",
    "hydrostatic_stiffness": "N/m, N, N m (translation/rotation DOF pairs; rotations in rad)",
    "displaced_volume": "m^3", "waterplane_area": "m^2", "center_of_buoyancy": "m (n-frame, NED)",
    "cog": "m (n-frame, NED)", "mass": "kg",
}


def matrix(da: xr.DataArray, dofs=None) -> np.ndarray:
    """Numpy array in the usual layout X[..., i_force, j_motion] (influenced, radiating), for ``dofs``."""
    if dofs is not None:
        da = da.sel(radiating_dof=list(dofs), influenced_dof=list(dofs))
    return da.transpose(..., "influenced_dof", "radiating_dof").values
