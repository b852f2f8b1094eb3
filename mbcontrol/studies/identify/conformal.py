"""Conformal prediction intervals: the arithmetic, free of any model (pure numpy).

Scores are normalised: R = |y - mu(x)| / s(x), with mu a prediction and s > 0 a scale (the
unit of y). Two constructions (Barber, Candes, Ramdas, Tibshirani 2021, "Predictive inference
with the jackknife+", Ann. Statist. 49(1)):

- split conformal: n scores from a model fitted on other data; the interval for a new x is
  mu(x) +- q s(x) with q the k-th smallest score, k = ceil((1 - alpha)(n + 1)). If the n + 1
  points are exchangeable, coverage is >= 1 - alpha (and < 1 - alpha + 1/(n + 1) for scores
  without ties);
- CV+ (K-fold jackknife+): each score R_i comes from the model fitted without point i's fold
  k(i); the interval for a new x is [the floor(alpha (n + 1))-th smallest of mu_k(i)(x) -
  R_i s_k(i)(x), the k-th smallest of mu_k(i)(x) + R_i s_k(i)(x)]. Under exchangeability its
  coverage is >= 1 - 2 alpha - min(2 (1 - 1/K) / (n/K + 1), (1 - K/n) / (K + 1)) in the worst
  case (Theorem 4, folds of equal size); in practice about 1 - alpha.

With fewer than 1/alpha - 1 scores (n < 19 at 95 %) k > n: no finite interval exists
(`quantile_index` returns None).
"""
from __future__ import annotations

import math

import numpy as np


def quantile_index(n: int, alpha: float) -> int | None:
    """k = ceil((1 - alpha)(n + 1)), 1-based: the rank of the conformal quantile among n
    scores; None when k > n (too few scores for a finite interval)."""
    k = math.ceil((1 - alpha) * (n + 1) - 1e-9)     # (1 - alpha)(n + 1) may be whole: no float slip
    return k if k <= n else None


def cv_plus_guarantee(n: int, folds: int, alpha: float) -> float:
    """The worst-case coverage CV+ guarantees (Barber et al. 2021, Theorem 4): 1 - 2 alpha -
    min(2 (1 - 1/K) / (n/K + 1), (1 - K/n) / (K + 1)), for K folds of n/K points each."""
    K = folds
    return 1 - 2 * alpha - min(2 * (1 - 1 / K) / (n / K + 1), (1 - K / n) / (K + 1))


def split_interval(scores, centre, scale, alpha: float = 0.05):
    """Split conformal: (lo, hi) arrays, centre -/+ q scale, with q the k-th smallest of the
    calibration `scores` (`quantile_index`); (nan, nan) when there are too few."""
    scores = np.sort(np.asarray(scores, float))
    centre, scale = np.asarray(centre, float), np.asarray(scale, float)
    k = quantile_index(scores.size, alpha)
    if k is None:
        return np.full(centre.shape, np.nan), np.full(centre.shape, np.nan)
    q = scores[k - 1]
    return centre - q * scale, centre + q * scale


def cv_plus_interval(scores, fold, centres, scales, alpha: float = 0.05):
    """CV+: (lo, hi) arrays for m new points. scores: (n,) R_i; fold: (n,) the fold index of
    each score (0..K-1, the model that did not see point i); centres, scales: (K, m), each
    fold's model's prediction mu_k(x) and scale s_k(x) at the new points. (nan, nan) when
    there are too few scores."""
    scores, fold = np.asarray(scores, float), np.asarray(fold, int)
    centres, scales = np.atleast_2d(centres).astype(float), np.atleast_2d(scales).astype(float)
    n = scores.size
    k = quantile_index(n, alpha)
    if k is None:
        nan = np.full(centres.shape[1], np.nan)
        return nan, nan.copy()
    low = centres[fold] - scores[:, None] * scales[fold]        # (n, m)
    high = centres[fold] + scores[:, None] * scales[fold]
    # the floor(alpha (n+1))-th smallest of the lows is the (n + 1 - k)-th: the k-th largest
    return np.sort(low, axis=0)[n - k], np.sort(high, axis=0)[k - 1]
