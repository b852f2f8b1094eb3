"""Power matrices: a sweep's mean power over an (hs, period) table.

Energy flux, annual energy, NDBC spectra, Hm0/Te and occurrence tables live in the waves
package (`mbcontrol.waves`).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ...errors import InputError


def power_matrix(ds: xr.Dataset, variable: str = "mean_power_W", period: str = "tp",
                 reduce_dims=("seed",)) -> xr.DataArray:
    """The variable over an (hs, period) table, averaged over seeds; a sweep over a grid or
    over a list whose seas fall on one."""
    da = ds[variable].mean([d for d in reduce_dims if d in ds[variable].dims])
    if set(da.dims) - {"sea"}:
        raise InputError(f"power matrix: {variable} still varies over "
                         f"{sorted(set(da.dims) - {'sea'})}; select one value of each first")
    hs, per = np.unique(ds["hs"].values), np.unique(np.round(ds[period].values, 9))
    table = np.full((hs.size, per.size), np.nan)
    for k in range(ds.sizes["sea"]):
        i = np.searchsorted(hs, ds["hs"].values[k])
        j = np.searchsorted(per, round(float(ds[period].values[k]), 9))
        table[i, j] = float(da.isel(sea=k))
    return xr.DataArray(table, coords={"hs": hs, period: per}, dims=("hs", period),
                        name=variable, attrs={"units": "W"})
