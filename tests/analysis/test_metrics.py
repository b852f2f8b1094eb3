"""PTO metrics (mbcontrol.analysis.metrics) on records whose answers are known in closed form."""
import json
import math

import numpy as np
import pytest
import xarray as xr

from mbcontrol.analysis.metrics import electrical_power, pto_metrics, wecccomp_score
from mbcontrol.scene import Pto


def _record(t, force, x, controller=True):
    ds = xr.Dataset({"p__force": ("time", force), "p__position": ("time", x)},
                    coords={"time": t})
    ds.attrs["controller"] = json.dumps({"name": "test"} if controller else None)
    ds.attrs["wave"] = json.dumps({"type": "irregular", "ramp_s": 0.0})
    return ds


def test_held_force_power_is_the_exact_work():
    """x = sin t under a force held at F_k = -c v(t_k): the work over each step is
    -F_k (sin t_k+1 - sin t_k) exactly, while the mean of the sampled -F v is off by O(dt)."""
    dt, c = 0.2, 3.0
    t = np.arange(0, 20 * np.pi + dt / 2, dt)
    x, v = np.sin(t), np.cos(t)
    force = -c * v
    m = pto_metrics(_record(t, force, x), "p", 0.0)
    exact = np.sum(c * v[:-1] * np.diff(x)) / (t[-1] - t[0])
    assert m["mean_power_W"] == pytest.approx(exact, rel=1e-12)
    # continuous c v^2 averages c / 2; the held force differs by O(dt^2) in the mean
    assert m["mean_power_W"] == pytest.approx(c / 2, rel=0.02)


def test_continuous_force_uses_the_trapezoidal_rule():
    """A spring force -k x does no net work over whole cycles: the trapezoidal work telescopes
    to zero, where the held-force sum would report -k/2 sum dx^2 / T < 0."""
    dt, k = 0.1, 5.0
    t = np.arange(0, 2 * np.pi * 10 + dt / 2, dt)
    x = np.sin(t)
    m = pto_metrics(_record(t, -k * x, x, controller=False), "p", 0.0)
    assert abs(m["mean_power_W"]) < 1e-3 * k
    held = pto_metrics(_record(t, -k * x, x, controller=True), "p", 0.0)
    assert held["mean_power_W"] < -1e-3 * k


def test_limits_percentiles_and_violations():
    t = np.linspace(0, 100, 10001)
    x = 0.1 * np.sin(t)
    force = np.full_like(t, 50.0)
    force[t > 99] = 80.0                         # 1 % of the samples over a 60 N limit
    pto = Pto(name="p", body="b", force_max=60.0, stroke_max=0.08, efficiency=0.7)
    m = pto_metrics(_record(t, force, x), pto, 0.0)
    assert m["max_force"] == 80.0 and m["force_violation"] == pytest.approx(20.0)
    assert m["f98"] == pytest.approx(50.0)
    assert m["max_stroke"] == pytest.approx(0.1, rel=1e-6)
    assert m["stroke_violation"] == pytest.approx(0.02, rel=1e-4)
    # |sin| > 0.8 for 1 - 2 asin(0.8) / pi of the time, plus the force's last percent
    share = 1 - 2 * math.asin(0.8) / math.pi
    assert m["violation_fraction"] == pytest.approx(share + 0.01 * (1 - share), abs=0.005)
    # z98 of |0.1 sin|: 0.1 sin(0.98 pi / 2)
    assert m["z98"] == pytest.approx(0.1 * math.sin(0.98 * math.pi / 2), rel=1e-3)


def test_electrical_power_and_wecccomp_score_by_hand():
    assert np.allclose(electrical_power([10.0, -7.0], 0.7), [7.0, -10.0])
    dt = 0.01
    t = np.arange(0, 60 + dt / 2, dt)
    x = 0.05 * np.sin(2 * t)
    force = np.where(np.cos(2 * t) > 0, -40.0, 30.0)         # held, crude bang-bang law
    pto = Pto(name="p", body="b", force_max=60.0, stroke_max=0.08, efficiency=0.7)
    score = wecccomp_score(_record(t, force, x), pto)
    keep = t[:-1] >= 25.0 - 1e-9
    p = (-force[:-1] * np.diff(x) / dt)[keep]
    pe = np.where(p > 0, 0.7 * p, p / 0.7).mean()
    f98 = np.percentile(np.abs(force[t >= 25.0 - 1e-9]), 98)
    z98 = np.percentile(np.abs(x[t >= 25.0 - 1e-9]), 98)
    ec = pe / (2 + f98 / 60 + z98 / 0.08 - np.abs(p).mean() / np.percentile(np.abs(p), 98))
    assert score["EC"] == pytest.approx(ec, rel=1e-12)
    with pytest.raises(ValueError, match="finite force_max"):
        wecccomp_score(_record(t, force, x), "p")


def test_statistics_start_after_the_ramp_and_the_controller_warm_up():
    """A sea with a 10 s ramp and a controller whose warm-up ended at 30 s: the window starts
    at the later (30 s) and says why; without a warm-up it starts after the ramp."""
    from mbcontrol.analysis.metrics import analysis_window, statistics_window
    t = np.arange(0.0, 100.0, 0.5)
    ds = _record(t, np.zeros_like(t), np.zeros_like(t))
    ds.attrs["wave"] = json.dumps({"type": "jonswap", "ramp_s": 10.0})
    assert statistics_window(ds)["start_s"] == 10.0
    ds.attrs["controller"] = json.dumps({"name": "mpc", "warm_up_s": 30.0})
    info = statistics_window(ds)
    assert info["start_s"] == 30.0 and "warm-up (30 s)" in info["note"]
    assert analysis_window(ds).sum() == np.sum(t >= 30.0)
