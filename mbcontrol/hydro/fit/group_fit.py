"""One coupled DOF group's radiation fit chosen among congruence scalings, and a fit reused for an
identical group (identical bodies without hydrodynamic interaction cost one fit)."""
from __future__ import annotations

import numpy as np

from .fit_error import INTERP_WEIGHT, _gate
from .passivity import _response
from .vector_fit import _congruence_scale, _fit_group, _unit_class


def _best_scaled_fit(common, settings, dofs, passive, judge=None):
    """Fit one group under each distinct congruence scaling (per unit class, per DOF) and keep the
    model that meets tol, then one whose passivity enforcement kept C B = K(0+), then the fewest
    states, then the most accurate (error on the group's data).

    Which weighting lets the fit reach the tolerance soonest depends on the data: per-DOF scaling
    helps a small, clean entry; per-class scaling keeps the fit off a small, noisy one."""
    w, Kg, _, bem, ainf, inband = common
    tol = settings["tol"]
    options = {"unit class": [_unit_class(d) for d in dofs], "per DOF": list(dofs)}
    if np.allclose(_congruence_scale(Kg, options["unit class"]), _congruence_scale(Kg, options["per DOF"])):
        options.pop("per DOF")
    best, tried = None, []
    for label, classes in options.items():
        args = (*common, classes)
        *abc, rep, before = _fit_group(*args, **settings, judge=judge)
        # passive fits may need more poles: fit deeper, retry; only if the unconstrained fit met
        # the target (else more poles do not help, and the retry doubles a long fit's time)
        if passive and not rep["passivity"]["met"] and rep["error_gate"] <= tol:
            *abc2, rep2, _ = _fit_group(*args, **settings, vf_frac=0.15, judge=judge)
            if rep2["passivity"]["error_after"] < rep["passivity"]["error_after"]:
                abc, rep = abc2, {**rep2, "deeper_vector_fit": True}
        err = group_error(abc, common, judge)
        markov_dropped = rep.get("passivity", {}).get("markov_kept") is False
        tried.append({"scaling": label, "n_states": int(abc[0].shape[0]), "error": float(err),
                      "markov_dropped": markov_dropped})
        key = (err > tol, markov_dropped, abc[0].shape[0], err)
        if best is None or key < best[0]:
            best = (key, abc, {**rep, "scaling": label}, before)
    _, abc, rep, before = best
    return abc, {**rep, "scalings_tried": tried}, before


def group_error(abc, common, judge=None) -> float:
    """The error that gates a group's fit (A, B, C): on its kernel data (``common`` as
    _best_scaled_fit takes it), or the device response's through ``judge``."""
    w, Kg, _, bem, ainf, inband = common
    fit = _response(*abc, None, w, 1e10)
    return (_gate(fit, Kg, w, ainf, bem, inband) if judge is None
            else float(np.max(judge(fit) * np.where(bem, 1.0, INTERP_WEIGHT))))


SAME_GROUP = 1e-6    # groups whose kernel data agree to this (relative; BEM round-off of
# identical bodies solved apart is ~1e-9) are candidates to share one fit


def same_group_fit(done, common, markov, judge, tol):
    """A fit already made for an identical group (``done``: [(common, markov, abc, rep, before,
    its error there)]), reused when its data agree to SAME_GROUP and its error on this group,
    judged as this group's own fit would be (its device response differs: another place in the
    chain), meets ``tol`` or is no worse than where it was made (a tolerance the data do not
    allow); else None. Identical bodies without hydrodynamic interaction then cost one fit."""
    Kg = common[1]
    size = max(float(np.max(np.abs(Kg))), 1e-300)
    for other, other_markov, abc, rep, before, made_err in done:
        if other[1].shape != Kg.shape or (markov is None) != (other_markov is None):
            continue
        same = (np.max(np.abs(other[1] - Kg)) <= SAME_GROUP * size
                and np.allclose(other[4], common[4], rtol=SAME_GROUP, atol=0)
                and (markov is None or np.allclose(other_markov, markov, rtol=SAME_GROUP,
                                                   atol=SAME_GROUP * np.max(np.abs(markov)))))
        if not same:
            continue
        err = group_error(abc, common, judge)
        if err <= max(tol, made_err * (1 + 1e-9)):
            return abc, {**rep, "error_gate": err, "reused": True}, before
    return None
