"""Conformal calibration of prediction intervals (mbcontrol.studies.identify.conformal and
.calibration) on synthetic data with a known model error, pure numpy: the finite-sample
quantile index, split conformal's coverage band and CV+'s coverage over 200 seeds, where a
parametric interval that ignores the model error falls short; the folds over runs and the hull
with the parametric interval."""
from types import SimpleNamespace

import numpy as np
import pytest

from mbcontrol.studies.identify.calibration import (calibrated_rows, folds, quantile_index_min,
                                                    scale)
from mbcontrol.studies.identify.conformal import (cv_plus_guarantee, cv_plus_interval,
                                                  quantile_index, split_interval)

ALPHA = 0.05
SEEDS = 200
N = 40             # calibration points (runs x channels on the flume: 20-62)
K = 4              # CV+ folds of N / K points
M = 200            # new points per seed


@pytest.mark.parametrize("n, alpha, k", [
    (19, 0.05, 19), (18, 0.05, None), (62, 0.05, 60), (20, 0.05, 20),
    (39, 0.05, 38),        # (1 - alpha)(n + 1) = 38 exactly: no float slip to 39
    (99, 0.05, 95), (100, 0.05, 96), (12, 0.2, 11), (4, 0.2, 4), (3, 0.2, None)])
def test_quantile_index_is_the_finite_sample_rank(n, alpha, k):
    assert quantile_index(n, alpha) == k


def test_fewest_scores_for_a_finite_quantile():
    assert quantile_index_min(0.05) == 19 and quantile_index_min(0.2) == 4


def _truth(x):
    return 1.0 + 2.0 * x + 1.5 * x ** 2


def _sample(rng, n):
    """Amplitudes with a relative error growing with x (heteroscedastic): 5-15 % sd."""
    x = rng.uniform(0.0, 1.0, n)
    return x, _truth(x) * (1.0 + (0.05 + 0.1 * x) * rng.standard_normal(n))


def _fit(x, y):
    """The 'model': a straight line (the truth is curved) shrunk by 5 % (a bias): a model
    error no parameter covariance describes. Returns predict(x)."""
    b, a = np.polyfit(x, y, 1)
    return lambda z: 0.95 * (a + b * z)


def _parametric(x, y, model, z):
    """What an interval from the fit's own residual spread alone gives: 1.96 times the in-sample
    RMS absolute residual over sqrt(n) (the line's standard error), the analogue of the
    parameter-covariance interval without model error."""
    return 1.96 * np.sqrt(np.mean((y - model(x)) ** 2) / x.size) * np.ones_like(z)


def test_split_conformal_covers_within_its_band():
    """Split conformal with relative scores |y - mu| / mu: over 200 seeds the mean coverage of
    new points lies in [1 - alpha, 1 - alpha + 1/(n + 1)] (its exact band for continuous
    scores), within 3 standard errors of 200 seeds (the coverage of one seed is Beta(k, n + 1 -
    k): sd 0.033 at n = 40); with k - 1 for k (an off-by-one) it would be 1/41 lower."""
    share = []
    for seed in range(SEEDS):
        rng = np.random.default_rng(seed)
        model = _fit(*_sample(rng, 60))
        xc, yc = _sample(rng, N)
        x, y = _sample(rng, M)
        lo, hi = split_interval(np.abs(yc - model(xc)) / model(xc), model(x), model(x), ALPHA)
        share.append(np.mean((lo <= y) & (y <= hi)))
    k = quantile_index(N, ALPHA)
    sd = np.sqrt(k * (N + 1 - k) / ((N + 1) ** 2 * (N + 2)))
    band = 3 * np.hypot(sd / np.sqrt(SEEDS), np.sqrt(ALPHA * (1 - ALPHA) / (SEEDS * M)))
    mean = float(np.mean(share))
    assert 1 - ALPHA - band <= mean <= 1 - ALPHA + 1 / (N + 1) + band, (mean, band)


def test_cv_plus_covers_where_the_parametric_interval_does_not():
    """CV+ over K folds of equal size, the model refitted on the other folds, relative scores:
    mean coverage over 200 seeds at least the worst-case guarantee and, in practice, 1 - alpha
    within 3 standard errors; the interval from the fit's residual spread alone (no model
    error) covers far less. Each new point's interval is built from every fold's model."""
    share, share_parametric = [], []
    for seed in range(SEEDS):
        rng = np.random.default_rng(1000 + seed)
        xc, yc = _sample(rng, N)
        x, y = _sample(rng, M)
        fold = np.arange(N) % K
        scores, centres, scales = np.empty(N), [], []
        for k in range(K):
            model = _fit(xc[fold != k], yc[fold != k])
            mu = model(xc[fold == k])
            scores[fold == k] = np.abs(yc[fold == k] - mu) / mu
            centres.append(model(x))
            scales.append(model(x))
        lo, hi = cv_plus_interval(scores, fold, centres, scales, ALPHA)
        share.append(np.mean((lo <= y) & (y <= hi)))
        model = _fit(xc, yc)
        half = _parametric(xc, yc, model, x)
        share_parametric.append(np.mean(np.abs(y - model(x)) <= half))
    mean = float(np.mean(share))
    se = np.std(share, ddof=1) / np.sqrt(SEEDS)
    assert mean >= cv_plus_guarantee(N, K, ALPHA)
    assert mean >= 1 - ALPHA - 3 * se, (mean, se)
    assert mean <= 1 - ALPHA + 1 / (N + 1) + 3 * se + 0.02, mean      # not vacuous either
    assert np.mean(share_parametric) < 0.5, np.mean(share_parametric)


def test_cv_plus_with_one_model_is_split_conformal():
    """Every fold's model the same: CV+ is the split interval mu -/+ q s."""
    rng = np.random.default_rng(3)
    scores, fold = rng.exponential(size=30), np.arange(30) % 3
    centre, s = rng.uniform(1, 2, 5), rng.uniform(0.1, 0.2, 5)
    lo, hi = cv_plus_interval(scores, fold, [centre] * 3, [s] * 3, ALPHA)
    lo_split, hi_split = split_interval(scores, centre, s, ALPHA)
    np.testing.assert_allclose(lo, lo_split)
    np.testing.assert_allclose(hi, hi_split)
    assert np.all(np.isnan(cv_plus_interval(scores[:10], fold[:10], [centre] * 3, [s] * 3,
                                            ALPHA)[0]))


def _run(name, group, omega):
    return SimpleNamespace(name=name, group=group, omega=omega)


def test_folds_leave_a_series_out_or_deal_frequencies():
    runs = [_run("4021_1", "series 4", 4.95), _run("4021_2", "series 4", 4.95),
            _run("5061_1", "series 5", 5.42), _run("6081_1", "series 6", 5.86)]
    how, parts = folds(runs)
    assert how == "leave one series out"
    assert parts == [("series 4", {"4021_1", "4021_2"}), ("series 5", {"5061_1"}),
                     ("series 6", {"6081_1"})]
    one = [_run(f"4{i:02d}1_{r}", "series 4", w) for i, w in enumerate(
        (4.95, 5.19, 5.42, 5.86, 6.07, 7.0, 7.83)) for r in (1, 2)]
    how, parts = folds(one)
    assert how == "5 folds of frequencies within series 4"
    held = [names for _, names in parts]
    assert sorted(n for h in held for n in h) == sorted(r.name for r in one)   # each once
    assert held[0] == {"4001_1", "4001_2", "4051_1", "4051_2"}   # repeats together, dealt in turn
    assert folds([_run("4021_1", "series 4", 4.95)]) == ("none", [])


def test_scale_widens_on_resonance_flanks_and_interval_is_the_hull():
    assert scale(2.0, 0.0) == 2.0
    assert scale(2.0, -10.0) == pytest.approx(2.0 * np.hypot(1, 3.0))   # KAPPA 0.3
    rows = [{"run": "a", "channel": "Roll", "interval_95": [0.9, 1.1]},
            {"run": "b", "channel": "Roll", "interval_95": [0.5, 2.0]},
            {"run": "c", "channel": "Roll", "interval_95": [0.9, 1.1]}]
    out = calibrated_rows(rows, {("a", "Roll"): [0.8, 1.05], ("b", "Roll"): [0.7, 1.5]})
    assert [r["interval_95"] for r in out] == [[0.8, 1.1], [0.5, 2.0], [0.9, 1.1]]
    assert [r["interval_95_parametric"] for r in out] == [r["interval_95"] for r in rows]
