"""The sea, in one place: spectra and their moments, dispersion, realisations (regular,
irregular, measured records) and the one band-clipping rule, excitation synthesis, directional spreading, energy flux
in finite depth, site files (weighted sea lists, NDBC buoy spectra, occurrence tables) and
annual energy.

Modules, one concept each: `spectra`, `dispersion`, `synthesis`, `realisation`, `record` (a
measured elevation record, a file or a series, as a wave), `excitation`, `spreading`, `flux`,
`sites`, `annual`, `local_field` (the incident field near a body as Chebyshev series, for
nonlinear Froude-Krylov forces). Everything public is re-exported here (`from mbcontrol.waves
import irregular`). The package imports no stage of the flow.
"""
from .annual import HOURS_PER_YEAR, annual_energy_MWh, bin_seas
from .dispersion import group_velocities, group_velocity, wavenumber
from .excitation import (coefficient_offsets, coefficient_series, excitation_at_offsets, excitation_impulse_response,
                         excitation_series, interpolate_complex)
from .local_field import LocalField, band_field, choose_field, field_rows_offsets, field_rows_series
from .direct_field import direct_elevation, direct_pressure
from .flux import deep_water_flux, energy_flux, spectrum_energy_flux
from .realisation import (DEFAULT_BAND, Wave, band_limits, from_args, irregular, regular,
                          repeat_period, variance_outside)
from .record import from_elevation, from_record, read_elevation
from .sites import (SPREAD_MAX_DEG, WEIGHT_SUM_TOLERANCE, SeaState, grid, occurrence,
                    read_ndbc_spectra, read_seas, read_year_weights, site_energy_flux)
from .spreading import Spreading, component_directions, spread_from_s
from .spreading import from_settings as spreading_from_settings
from .spectra import gamma_for_te_over_tp, jonswap_spectrum, moment, spectral_hm0_te, te_over_tp
from .synthesis import ramp

__all__ = [
    "Wave", "regular", "irregular", "from_args", "from_elevation", "band_limits",
    "variance_outside", "DEFAULT_BAND", "ramp", "repeat_period", "from_record", "read_elevation",
    "jonswap_spectrum", "moment", "spectral_hm0_te", "te_over_tp", "gamma_for_te_over_tp",
    "wavenumber", "group_velocity", "group_velocities",
    "excitation_series", "excitation_at_offsets", "excitation_impulse_response",
    "interpolate_complex", "coefficient_series", "coefficient_offsets",
    "energy_flux", "spectrum_energy_flux", "deep_water_flux",
    "SeaState", "grid", "read_seas", "read_year_weights", "site_energy_flux",
    "read_ndbc_spectra", "occurrence", "SPREAD_MAX_DEG", "WEIGHT_SUM_TOLERANCE",
    "Spreading", "component_directions", "spread_from_s", "spreading_from_settings",
    "HOURS_PER_YEAR", "annual_energy_MWh", "bin_seas",
    "LocalField", "band_field", "choose_field", "direct_elevation", "direct_pressure", "field_rows_offsets",
    "field_rows_series",
]
