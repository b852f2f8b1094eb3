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
from ..lazy import face

# name -> (submodule, its name there): loaded on first use, so that a run's wave imports no
# site file reader (xarray, pandas) and no special functions it does not use
_WHERE = {
    "HOURS_PER_YEAR": ("annual", "HOURS_PER_YEAR"),
    "annual_energy_MWh": ("annual", "annual_energy_MWh"), "bin_seas": ("annual", "bin_seas"),
    "group_velocities": ("dispersion", "group_velocities"),
    "group_velocity": ("dispersion", "group_velocity"), "wavenumber": ("dispersion", "wavenumber"),
    "coefficient_offsets": ("excitation", "coefficient_offsets"),
    "coefficient_series": ("excitation", "coefficient_series"),
    "excitation_at_offsets": ("excitation", "excitation_at_offsets"),
    "excitation_impulse_response": ("excitation", "excitation_impulse_response"),
    "excitation_series": ("excitation", "excitation_series"),
    "interpolate_complex": ("excitation", "interpolate_complex"),
    "LocalField": ("local_field", "LocalField"), "band_field": ("local_field", "band_field"),
    "choose_field": ("local_field", "choose_field"),
    "field_rows_offsets": ("local_field", "field_rows_offsets"),
    "field_rows_series": ("local_field", "field_rows_series"),
    "direct_elevation": ("direct_field", "direct_elevation"),
    "direct_pressure": ("direct_field", "direct_pressure"),
    "deep_water_flux": ("flux", "deep_water_flux"), "energy_flux": ("flux", "energy_flux"),
    "spectrum_energy_flux": ("flux", "spectrum_energy_flux"),
    "DEFAULT_BAND": ("realisation", "DEFAULT_BAND"), "Wave": ("realisation", "Wave"),
    "band_limits": ("realisation", "band_limits"), "from_args": ("realisation", "from_args"),
    "irregular": ("realisation", "irregular"), "regular": ("realisation", "regular"),
    "repeat_period": ("realisation", "repeat_period"),
    "variance_outside": ("realisation", "variance_outside"),
    "from_elevation": ("record", "from_elevation"), "from_record": ("record", "from_record"),
    "read_elevation": ("record", "read_elevation"),
    "SPREAD_MAX_DEG": ("sites", "SPREAD_MAX_DEG"),
    "WEIGHT_SUM_TOLERANCE": ("sites", "WEIGHT_SUM_TOLERANCE"),
    "SeaState": ("sites", "SeaState"), "grid": ("sites", "grid"),
    "occurrence": ("sites", "occurrence"), "read_ndbc_spectra": ("sites", "read_ndbc_spectra"),
    "read_seas": ("sites", "read_seas"), "read_year_weights": ("sites", "read_year_weights"),
    "site_energy_flux": ("sites", "site_energy_flux"), "Spreading": ("spreading", "Spreading"),
    "component_directions": ("spreading", "component_directions"),
    "spread_from_s": ("spreading", "spread_from_s"),
    "spreading_from_settings": ("spreading", "from_settings"),
    "gamma_for_te_over_tp": ("spectra", "gamma_for_te_over_tp"),
    "jonswap_spectrum": ("spectra", "jonswap_spectrum"), "moment": ("spectra", "moment"),
    "spectral_hm0_te": ("spectra", "spectral_hm0_te"), "te_over_tp": ("spectra", "te_over_tp"),
    "ramp": ("synthesis", "ramp"),
}

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

__getattr__, __dir__ = face(__name__, globals(), _WHERE)
