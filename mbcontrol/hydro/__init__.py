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
from ..lti import phasor
from .data.netcdf import read_netcdf, write_netcdf_atomic
from .fit.baseline import fit_radiation_hankel
from .bem.solve import cache_key, compute
from .data.dataset import matrix
from .data.frames import dof_map, shift_matrix, skew, to_body_frames, zup_to_ned
from .data.headings import (axisymmetric_headings, covering_headings, covers_circle, heading_matrix,
                            headings_for_spread, headings_line)
from .mesh.geometry import RIGID_DOFS, BemBody, hull_mesh, lid_mesh, validate_body
from .model import HydroModel, fit_hydro_model, fit_method, geometry_dict, load_hydro_data, load_hydro_model
from .fit.passivity import PassivityReport, absorbed_energy, enforce_passivity, passivity_test
from .fit.array_fit import fit_radiation_columns
from .fit.kernel import convolution_force, impulse_response, kernel_data
from .fit.radiation import RadiationModel, fit_radiation
from .bem.isolated import compute_isolated
from .data.headings import SECTOR_SIGMAS
from .fit.response_error import Device, response_error_on
from .fit.ssforms import state_blocks
from .mesh.large_angle import buoyancy
from .mesh.large_angle import potential as buoyancy_potential
from .mesh.panels import Panels, body_panels, hydrostatic_pressure, pressure_wrench
from .mesh.surface_sums import calm_water_function, pressure_wrench_function
from .mesh.axisymmetric import AxisymmetricFK
from .mesh.axisymmetric import from_geometry as axisymmetric_fk
from .model import obstacle_bodies, recording_served_fits, shipped_fits_dir
from .fit.plots import hydro_figure
from .source import converted_source, with_displaced_masses

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
