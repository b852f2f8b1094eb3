"""Power performance at scale: sweeps over sea states, seeds, controller settings, plant and
scene parameters, closed loop, serially or on Dask, resumable from a store on disk; power
matrices, capture widths, annual energy at a site.

Modules: `cases` (seas, grids, the seas CSV, cases and their keys), `store` (records on disk,
the assembled Dataset), `runner` (serial and Dask execution), `power` (power matrix),
`study` (`sweep`), `made_by` (its provenance), `plots`, `records` (a folder of measured
elevation records as the seas), `frequency_domain` (`frequency_sweep`: linear theory of every
sea at once, milliseconds; its summary in `frequency_summary`).
The seas, energy flux, annual energy, NDBC spectra and occurrence tables are
`mbcontrol.waves`' (re-exported here).
"""
from ...waves import (SeaState, annual_energy_MWh, energy_flux, grid, occurrence, read_seas,
                     site_energy_flux)
from .budget import table as budget_table
from .frequency_domain import frequency_sweep, froude_seas, sea_powers
from .frequency_summary import compare_domains
from .plots import plot_sweep
from .power import power_matrix
from .records import MeasuredSea, read_records
from .resource import Resource, ndbc_resource
from .study import sweep

__all__ = ["sweep", "SeaState", "grid", "read_seas", "energy_flux", "annual_energy_MWh",
           "power_matrix", "occurrence", "site_energy_flux", "budget_table", "plot_sweep",
           "MeasuredSea", "read_records",
           "Resource", "ndbc_resource", "frequency_sweep", "sea_powers", "froude_seas",
           "compare_domains"]
