"""Hydrodynamics: Capytaine BEM runs, frame maps to NED body frames, radiation models.

Sub-packages by stage, each importing only those before it (tests/test_layout.py):
``mesh`` (the wetted surfaces) < ``data`` (the body-frame dataset, frame maps, NetCDF) <
``bem`` (Capytaine runs) and ``readers`` (WAMIT, BEMIO, Capytaine files) < ``fit`` (radiation
kernel, fits judged by the device's response, passivity) < ``model`` (the HydroModel a plant uses).

Dataset layout returned by :func:`compute` (SI units, NED body frames at each CoG,
time convention e^{-iωt} as Capytaine's, excitation per unit wave amplitude at the n-frame origin):

- coords ``omega`` (rad/s), ``radiating_dof``/``influenced_dof`` (``<body>__<Dof>``),
  ``wave_direction`` (rad, NED: direction waves travel to, +x towards +y starboard), ``body``, ``xyz``
- ``added_mass``, ``radiation_damping`` (omega, radiating_dof, influenced_dof);
  ``added_mass_inf``, ``added_mass_zero``, ``hydrostatic_stiffness`` (radiating_dof, influenced_dof)
- ``excitation_force`` = ``froude_krylov_force`` + ``diffraction_force`` (wave_direction, omega, influenced_dof)
- ``displaced_volume``, ``waterplane_area``, ``mass`` (body); ``center_of_buoyancy``, ``cog`` (body, xyz)

Wave directions: the excitation between the data's headings, the headings a spread sea needs and
axisymmetric data (module data.headings; `HydroModel.excitation_at`).

Phasors: the data stay in e^{-iωt} on disk and in memory (files, the shipped fits and their cache
keys are unchanged); above this package phasors are e^{+iωt}, the toolbox's public convention
(python-control's, :mod:`mbcontrol.lti`). The one conversion is :func:`phasor` (the complex
conjugate), used by `HydroModel.excitation_phasor`.

Arrays: a mirror-symmetric layout is solved on its planes (module bem.array_bem); many bodies' radiation
is fitted column by column (module fit.array_fit, :func:`fit_radiation_columns`).
"""
from ..lazy import face
from ..lti import phasor

# name -> (submodule, its name there): loaded on first use, so that a plant built from stored
# data and a cached fit imports no BEM solver, reader, panel method or plotting
_WHERE = {
    "read_netcdf": ("data.netcdf", "read_netcdf"),
    "write_netcdf_atomic": ("data.netcdf", "write_netcdf_atomic"),
    "fit_radiation_hankel": ("fit.baseline", "fit_radiation_hankel"),
    "cache_key": ("bem.solve", "cache_key"), "compute": ("bem.solve", "compute"),
    "matrix": ("data.dataset", "matrix"), "dof_map": ("data.frames", "dof_map"),
    "shift_matrix": ("data.frames", "shift_matrix"), "skew": ("data.frames", "skew"),
    "to_body_frames": ("data.frames", "to_body_frames"), "zup_to_ned": ("data.frames", "zup_to_ned"),
    "axisymmetric_headings": ("data.headings", "axisymmetric_headings"),
    "covering_headings": ("data.headings", "covering_headings"),
    "covers_circle": ("data.headings", "covers_circle"),
    "heading_matrix": ("data.headings", "heading_matrix"),
    "headings_for_spread": ("data.headings", "headings_for_spread"),
    "headings_line": ("data.headings", "headings_line"),
    "SECTOR_SIGMAS": ("data.headings", "SECTOR_SIGMAS"),
    "RIGID_DOFS": ("mesh.geometry", "RIGID_DOFS"), "BemBody": ("mesh.geometry", "BemBody"),
    "hull_mesh": ("mesh.geometry", "hull_mesh"), "lid_mesh": ("mesh.geometry", "lid_mesh"),
    "validate_body": ("mesh.geometry", "validate_body"), "HydroModel": ("model", "HydroModel"),
    "fit_hydro_model": ("model", "fit_hydro_model"), "fit_method": ("model", "fit_method"),
    "geometry_dict": ("model", "geometry_dict"), "load_hydro_data": ("model", "load_hydro_data"),
    "load_hydro_model": ("model", "load_hydro_model"),
    "obstacle_bodies": ("model", "obstacle_bodies"),
    "recording_served_fits": ("model", "recording_served_fits"),
    "shipped_fits_dir": ("model", "shipped_fits_dir"),
    "PassivityReport": ("fit.passivity", "PassivityReport"),
    "absorbed_energy": ("fit.passivity", "absorbed_energy"),
    "enforce_passivity": ("fit.passivity", "enforce_passivity"),
    "passivity_test": ("fit.passivity", "passivity_test"),
    "fit_radiation_columns": ("fit.array_fit", "fit_radiation_columns"),
    "convolution_force": ("fit.kernel", "convolution_force"),
    "impulse_response": ("fit.kernel", "impulse_response"),
    "kernel_data": ("fit.kernel", "kernel_data"),
    "RadiationModel": ("fit.radiation", "RadiationModel"),
    "fit_radiation": ("fit.radiation", "fit_radiation"),
    "compute_isolated": ("bem.isolated", "compute_isolated"),
    "Device": ("fit.response_error", "Device"),
    "response_error_on": ("fit.response_error", "response_error_on"),
    "state_blocks": ("fit.ssforms", "state_blocks"),
    "buoyancy": ("mesh.large_angle", "buoyancy"),
    "buoyancy_potential": ("mesh.large_angle", "potential"),
    "Panels": ("mesh.panels", "Panels"), "body_panels": ("mesh.panels", "body_panels"),
    "hydrostatic_pressure": ("mesh.panels", "hydrostatic_pressure"),
    "pressure_wrench": ("mesh.panels", "pressure_wrench"),
    "calm_water_function": ("mesh.surface_sums", "calm_water_function"),
    "pressure_wrench_function": ("mesh.surface_sums", "pressure_wrench_function"),
    "AxisymmetricFK": ("mesh.axisymmetric", "AxisymmetricFK"),
    "axisymmetric_fk": ("mesh.axisymmetric", "from_geometry"),
    "hydro_figure": ("fit.plots", "hydro_figure"),
    "converted_source": ("source", "converted_source"),
    "with_displaced_masses": ("source", "with_displaced_masses"),
}

__all__ = [
    "read_netcdf", "write_netcdf_atomic", "phasor",
    "BemBody", "RIGID_DOFS", "compute", "cache_key", "matrix", "validate_body", "hull_mesh", "lid_mesh",
    "to_body_frames", "dof_map", "shift_matrix", "skew", "zup_to_ned",
    "RadiationModel", "fit_radiation", "fit_radiation_columns", "impulse_response", "convolution_force", "kernel_data",
    "PassivityReport", "passivity_test", "enforce_passivity", "absorbed_energy", "fit_radiation_hankel",
    "headings_for_spread", "headings_line", "covering_headings", "covers_circle",
    "heading_matrix", "axisymmetric_headings",
    "HydroModel", "load_hydro_model", "load_hydro_data", "fit_hydro_model", "fit_method", "geometry_dict",
    "compute_isolated", "SECTOR_SIGMAS", "Device", "response_error_on", "state_blocks", "buoyancy",
    "buoyancy_potential", "Panels", "body_panels", "hydrostatic_pressure", "pressure_wrench",
    "pressure_wrench_function", "calm_water_function",
    "AxisymmetricFK", "axisymmetric_fk",
    "recording_served_fits", "obstacle_bodies", "shipped_fits_dir", "converted_source", "with_displaced_masses", "hydro_figure",
]

__getattr__, __dir__ = face(__name__, globals(), _WHERE)
