"""Order selection around passivity enforcement for one radiation-fit DOF group.

:func:`make_passive` is called by :mod:`mbcontrol.hydro.fit.vector_fit` with the group's refit and
error gate; the enforcement itself (KYP-lemma SDP on C) and the exact test are in
:mod:`mbcontrol.hydro.fit.passivity`.
"""
from __future__ import annotations

import numpy as np

from .passivity import enforce_passivity, passivity_test

LAWSON_STEPS = 3   # reweighted enforcements after the first, while the gate is missed,
LAWSON_REACH = 3.0  # tried only within this factor of the target (farther, it did not get there)


def make_passive(trial, error, abc, err, *, target, n_max, max_states, omega, H, weights, dc_zero,
                 markov, profile=None):
    """Order selection around :func:`enforce_passivity`, used by ``fit_radiation`` per DOF group.

    abc = (A, B, C) is the selected model and err its error; trial(r) -> (error, (A, B, C)) refits
    at order r; error(A, B, C) is the fit's error gate. A model that is not passive gets C
    enforced; while the enforced error exceeds ``target`` the order grows ~1.4× (a larger basis
    leaves more freedom to the passive fit) up to min(n_max, max_states), and once an order meets
    it the smallest passing order is bisected for. C B = ``markov`` is kept if some order meets the
    target with it; otherwise the search is repeated without it (a passive model obeys the sum rule
    C B = (2/π)∫Re K dω, so data whose A∞ or tail disagree with their B cannot have both). If no
    order meets the target, the lowest-error passive model is returned. Returns
    (A, B, C, error, info); info is JSON-serialisable.

    The enforcement minimises a weighted least-squares misfit, the gate is a worst-case error: an
    enforced C that spreads its change evenly can miss the gate at a few frequencies (the OSWEC's
    small low-frequency damping). So if the chosen model misses the target by at most
    LAWSON_REACH, ``profile(A, B, C)`` -> (nω,) error / target per enforcement frequency raises
    the weights where it exceeds 1 (by that factor, at most 4x per step, LAWSON_STEPS steps:
    Lawson's reweighting towards the minimax fit), each step kept only if the gate error falls.
    Only the chosen order is reweighted: per order it cost flap_pair 40x the time.
    """
    r0 = abc[0].shape[0]
    cap = min(n_max, int(max_states))
    info = {"order_before": int(r0), "error_before": float(err), "attempts": []}
    done = {}

    def attempt(r, mk):
        if (r, mk) in done:
            return done[r, mk]
        e, m = (err, abc) if r == r0 else trial(r)
        if m is None:
            done[r, mk] = None
            return None
        test = passivity_test(*m)
        if r == r0:
            info.update(passive_before=bool(test.passive), margin_before=float(test.margin))
        if test.passive:
            done[r, mk] = (*m, e, None)
            return done[r, mk]
        Cp, enf = enforce_passivity(*m, omega, H, weights, dc_zero=dc_zero, markov=markov if mk else None)
        ep = error(m[0], m[1], Cp)
        info["attempts"].append({"order": int(r), "error": float(ep), **enf})
        res = (m[0], m[1], Cp, ep, enf["constraints"]) if enf["enforced"] else None
        if mk and enf["enforced"] and "markov" not in enf["constraints"]:  # infeasible with C B = K(0+)
            done[r, True], done[r, False] = None, res
        else:
            done[r, mk] = res
        return done[r, mk]

    def ok(res):
        return res is not None and res[3] <= target

    def search(mk):
        lo = hi = r0
        while not ok(attempt(hi, mk)):
            lo, hi = hi, min(cap, int(np.ceil(1.4 * hi)))
            if hi <= lo:
                return None
        while hi - lo > 1:  # smallest passing order in (lo, hi]
            mid = (lo + hi) // 2
            lo, hi = (lo, mid) if ok(attempt(mid, mk)) else (mid, hi)
        return done[hi, mk]

    best = search(True) if markov is not None else None
    info["markov_kept"] = None if markov is None else best is not None
    if best is None:
        best = search(False)
    if best is None:
        found = [v for v in done.values() if v is not None]  # the fewest states within 2 % of the best
        emin = min((v[3] for v in found), default=np.inf)
        best = min((v for v in found if v[3] <= 1.02 * emin), key=lambda v: v[0].shape[0],
                   default=(*abc, err, None))
    if profile is not None and best[4] is not None and target < best[3] <= LAWSON_REACH * target:
        best = _reweighted(best, error, profile, target, omega, H, weights, dc_zero, markov, info)
    info.update(order_after=int(best[0].shape[0]), error_after=float(best[3]), target=float(target),
                met=bool(best[3] <= target), enforced=bool(info["attempts"]),
                seconds=float(sum(a["seconds"] for a in info["attempts"])))
    return (*best[:4], info)


def _reweighted(best, error, profile, target, omega, H, weights, dc_zero, markov, info):
    """Lawson steps on the chosen order's enforcement (make_passive): weights raised where the
    gate is missed, the enforced C kept only if its gate error falls with the same constraints."""
    A, B, C, err, kept = best
    wts, steps = np.asarray(weights, dtype=float), []
    for _ in range(LAWSON_STEPS):
        factor = profile(A, B, C)
        if factor.max() <= 1.0:        # the gate is missed elsewhere (the global norm)
            break
        wts = wts * np.clip(factor, 1.0, 4.0)
        C2, enf = enforce_passivity(A, B, C, omega, H, wts, dc_zero=dc_zero,
                                    markov=markov if "markov" in kept else None)
        e2 = error(A, B, C2)
        steps.append({"error": float(e2), "seconds": enf["seconds"]})
        if not (enf["enforced"] and e2 < err and set(enf["constraints"]) == set(kept)):
            break
        C, err = C2, e2
        if err <= target:
            break
    info["attempts"].append({"order": int(A.shape[0]), "error": float(err), "reweighted": steps,
                             "seconds": float(sum(s["seconds"] for s in steps))})
    return A, B, C, err, kept
