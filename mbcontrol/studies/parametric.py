"""Parametric (Mathieu) resonance: where a coordinate grows from a small offset in regular waves
that do not excite it, charted over period x height: a stability diagram.

A body whose restoring in one coordinate (roll, pitch) changes as it moves in another (heave)
is parametrically excited: when the waves drive that motion near twice the coordinate's
natural frequency, a small offset grows exponentially (the principal tongue of Mathieu's
equation, widening with the wave height) until the nonlinear restoring bounds it. The linear
model cannot show it: its stiffness does not change with the motion. `stability_map` runs each
(period, height) from rest with the coordinate offset and reports its growth, the largest
|coordinate| over the last `tail` seconds over the offset (above 1: it grew, below: it decayed).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..errors import InputError
from ..sim import simulate
from ..waves import regular


def stability_map(plant, coordinate: str, periods, heights, *, offset: float = 0.02,
                  duration: float = 300.0, tail: float = 50.0, dt: float = 0.02,
                  direction: float = 0.0, progress=None) -> xr.DataArray:
    """Growth of `coordinate` (a state name, e.g. "float__Roll") from `offset` (its units) in
    regular waves of each period (s) and height (m): DataArray (height, period), dimensionless,
    max |coordinate| over the last `tail` s divided by `offset`; NaN where a run failed (its
    error message in attrs["failures"])."""
    if coordinate not in plant.states:
        raise InputError(f"stability_map: coordinate {coordinate!r}: expected one of "
                         f"{', '.join(plant.states[:plant.n_q])}")
    if not 0 < tail < duration:
        raise InputError(f"stability_map: tail = {tail} s: expected 0 < tail < duration "
                         f"({duration} s)")
    periods, heights = np.asarray(periods, float), np.asarray(heights, float)
    growth = np.full((heights.size, periods.size), np.nan)
    failures = {}
    x0 = plant.x0()
    x0[plant.states.index(coordinate)] = offset
    for i, height in enumerate(heights):
        for j, period in enumerate(periods):
            try:
                ds = simulate(plant, regular(height, period, direction=direction),
                              duration=duration, dt=dt, x0=x0)
            except Exception as exc:            # a capsize or a diverged step: the map says so
                failures[f"H {height:g} m, T {period:g} s"] = str(exc).splitlines()[0][:200]
                continue
            t, values = ds["time"].values, ds[coordinate].values
            growth[i, j] = np.max(np.abs(values[t >= t[-1] - tail])) / abs(offset)
            if progress is not None:
                progress(i * periods.size + j + 1, heights.size * periods.size)
    return xr.DataArray(growth, dims=("height", "period"),
                        coords={"height": ("height", heights, {"units": "m"}),
                                "period": ("period", periods, {"units": "s"})},
                        name=f"{coordinate}_growth",
                        attrs={"units": "1", "coordinate": coordinate, "offset": offset,
                               "duration_s": duration, "tail_s": tail, "dt_s": dt,
                               "model": plant.name, "failures": failures})


def natural_period(plant, coordinate: str) -> float:
    """The period (s) of the linearised plant's mode that moves `coordinate` the most: its
    eigenvalue whose eigenvector has the largest share of that state (radiation included)."""
    from ..analysis import linearize
    values, vectors = np.linalg.eig(linearize(plant).A)
    row = plant.states.index(coordinate)
    oscillating = np.flatnonzero(values.imag > 1e-6)
    mode = oscillating[np.argmax(np.abs(vectors[row, oscillating]))]
    return float(2 * np.pi / abs(values[mode]))


def plot_stability_maps(maps: dict, path=None, *, natural_period: float | None = None):
    """Side-by-side growth maps {label: stability_map(...)} on one colour scale (log10 of the
    growth; 0 is neutral), with T_n / 2 marked when the coordinate's natural period is given."""
    import matplotlib.pyplot as plt

    from ..plotting import save
    fig, axes = plt.subplots(1, len(maps), figsize=(5.2 * len(maps), 4.0), squeeze=False,
                             sharey=True)
    for ax, (label, growth) in zip(axes[0], maps.items()):
        image = ax.pcolormesh(growth["period"], growth["height"],
                              np.log10(np.maximum(growth.values, 1e-3)), shading="nearest",
                              cmap="RdBu_r", vmin=-2, vmax=2)
        if natural_period is not None:
            ax.axvline(natural_period / 2, color="k", ls="--", lw=1,
                       label=f"half the natural period ({natural_period / 2:.2f} s)")
            ax.legend(loc="upper right", fontsize=8)
        ax.set_title(label, fontsize=10)
        ax.set_xlabel("wave period (s)")
    axes[0][0].set_ylabel("wave height (m)")
    bar = fig.colorbar(image, ax=axes[0].tolist())
    coordinate = next(iter(maps.values())).attrs["coordinate"]
    bar.set_label(f"log10 growth of {coordinate}\n(max over the last seconds / offset)")
    if path is not None:
        save(fig, path)
    return fig
