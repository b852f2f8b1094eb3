"""Annual energy: the mean power of each sea state weighted by its share of the year.

An occurrence table (Hm0 x Te bins, `sites.occurrence`) is turned into the sea states to
simulate by `bin_seas`: one sea per occupied bin at the bin's own centre, with Tp from the
centre's Te through the Te / Tp of the JONSWAP spectrum actually simulated. The power of a bin
is then that bin's own simulated power: no interpolation across bins (mean power grows like
Hm0^2, so a linear interpolation of it in Hm0 reads high) and no clipping of seas to the edge
of a coarser matrix. Records outside the table are counted (table.attrs["outside"]), not
silently assigned to an edge bin.

Units: powers in W, weights as shares of the year, energy in MWh with HOURS_PER_YEAR = 8766
(365.25 days).
"""
from __future__ import annotations

import numpy as np

from ..errors import WaveError
from .sites import SeaState
from .spectra import te_over_tp

HOURS_PER_YEAR = 8766.0


def annual_energy_MWh(mean_power_W, weights) -> float:
    """Mean annual energy production: sum_i w_i P_i x 8766 h, in MWh (weights: shares of the
    year; NaN powers count as 0 only where the weight is 0)."""
    p = np.asarray(mean_power_W, float)
    w = np.asarray(weights, float)
    if np.any(np.isnan(p) & (w > 0)):
        raise WaveError("annual energy: a sea state with weight > 0 has no power")
    return float(np.nansum(p * w) * HOURS_PER_YEAR / 1e6)


def bin_seas(table, gamma: float = 3.3) -> list[SeaState]:
    """The sea states of an occurrence table's occupied bins (row by row): Hm0 and Te at the
    bin centre, Tp = Te / te_over_tp(gamma), weight = the bin's share of the records."""
    ratio = te_over_tp(gamma)
    share = np.asarray(table.values, float)
    seas = []
    for i, hs in enumerate(np.asarray(table["hs"].values, float)):
        for k, te in enumerate(np.asarray(table["te"].values, float)):
            if share[i, k] > 0:
                seas.append(SeaState(float(hs), float(te) / ratio, gamma, float(share[i, k]),
                                     float(te)))
    return seas
