"""Extrapolation said aloud: a run whose wave frequency lies where the model was not fitted.

Two bands bound what a fitted model has seen: the wave frequencies of the runs its parameters
were fitted on (a prediction outside them extrapolates the identified values), and the band
of its radiation fit (`report["omega_fit"]`: above it, the radiation model's K(jω) is the
state-space fit's extrapolation, not BEM data). On the flume data both matter: the radiation
fit stops at 6.67 rad/s (the last BEM frequency under the mesh limit, 6.99 rad/s), under 13 of
the 31 runs (up to 9.3 rad/s), where two fits of equal in-band error moved the identified sway
by 1.2 points of RMS error (issue 20).
Runs are flagged in the amplitude rows ("extrapolated": the reasons, empty when none), drawn
as such in `report.plot_amplitudes`, and warned about once per problem.
"""
from __future__ import annotations

import warnings


class ExtrapolationWarning(UserWarning):
    """Runs at wave frequencies the model was not fitted on."""


def radiation_limit(problem) -> float | None:
    """Highest frequency (rad/s) the radiation fit of the problem's plants used (None: no
    radiation model)."""
    limits = []
    for key in problem.groups:
        hydro = problem.plant(key).hydro
        if hydro is not None and hydro.radiation.order:
            limits.append(float(hydro.radiation.report["omega_fit"][1]))
    return min(limits) if limits else None


def reasons(problem, omega: float) -> list[str]:
    """Why a run at omega (rad/s) is an extrapolation of `problem`'s model (empty: it is not)."""
    out = []
    band = getattr(problem, "fitted_band", None)
    if band is not None and not band[0] - 1e-9 <= omega <= band[1] + 1e-9:
        out.append(f"outside the fitted runs' {band[0]:.3g}-{band[1]:.3g} rad/s")
    limit = radiation_limit(problem)
    if limit is not None and omega > limit + 1e-9:
        out.append(f"above the radiation fit's {limit:.3g} rad/s")
    return out


def warn(problem, what: str) -> list[str]:
    """One ExtrapolationWarning listing `problem`'s extrapolated runs (what: "fit" or
    "validation"); returns the messages."""
    flagged = {}
    for run in problem.runs:
        for reason in reasons(problem, run.omega):
            flagged.setdefault(reason, []).append(f"{run.name} ({run.omega:.3g})")
    messages = [f"{what} runs {', '.join(runs)} rad/s: {reason}, where the model extrapolates"
                for reason, runs in flagged.items()]
    for text in messages:
        warnings.warn(text, ExtrapolationWarning, stacklevel=3)
    return messages
