"""Whether a designed linear law can be deployed, and why it reaches the share of the bound
it does: robustness floors on its stability margins, and its power set against the bounds
with and without the linear model's envelope (analysis.envelope).

Floors (controllers.margins' quantities), from the defaults registry so one setting moves
design, export and the checks together: a gain margin of `design.gain_margin_min` (2: the
gains, or the device's impedance they were tuned to, may be off by that factor) and a phase
margin of `design.phase_margin_min_deg` (30 deg), the textbook 6 dB and 30 deg. `design` and
`export` tune within them by default (`robust=True`): the reactive tuner then keeps
min |1 + L| >= stability_floor(), which meets both floors (rm3, Hs 2 m, Tp 10 s: gain margin
1.03 -> 2.08, phase margin 12 -> 60 deg, 2 % less power predicted). The unconstrained optimum
(`--aggressive`, robust=False) is near the edge by construction: complex-conjugate control
cancels the device's reactance (sphere, H 2 m, T 8 s: gain margin 1.62, phase margin 20 deg).
No slowest-pole floor: on rm3 a mode no PTO force moves decays at 0.002 1/s whatever the law
(controllers.impedance.margin_function for any damping), so such a floor says nothing about
the law.
"""
from __future__ import annotations

import math

# the least distance s = min |1 + L| is evaluated by the tuner on the BEM data's grid, the
# margins on the state-space loop (radiation fit): room so that a law at the constraint still
# meets the floors in controllers.margins' figures (0.52 on the default floors, as before)
STABILITY_ROOM = 1.005


def floors() -> dict:
    """{"gain_margin": factor, "phase_margin_deg": deg}: the defaults registry's floors."""
    from mbcontrol import defaults
    gm, pm = float(defaults.get("design.gain_margin_min")), \
        float(defaults.get("design.phase_margin_min_deg"))
    if not (gm >= 1 and 0 <= pm < 180):
        from mbcontrol.errors import InputError
        raise InputError(f"defaults design.gain_margin_min = {gm:g} and "
                         f"design.phase_margin_min_deg = {pm:g}: expected a gain margin >= 1 "
                         f"and a phase margin in 0..180 deg")
    return {"gain_margin": gm, "phase_margin_deg": pm}


def stability_floor() -> float:
    """The least min |1 + L| a robust tuner keeps: the Nyquist curve s from -1 everywhere
    guarantees a gain margin of 1 / (1 - s) and a phase margin of 2 asin(s / 2); s is the
    larger of the two that meet floors(), times STABILITY_ROOM (gm 2, pm 30 deg: 0.5176 ->
    0.520, a gain margin of 2.08 and a phase margin of 30.1 deg at the least)."""
    f = floors()
    s = max(1 - 1 / f["gain_margin"], 2 * math.sin(math.radians(f["phase_margin_deg"]) / 2))
    return s * STABILITY_ROOM


def __getattr__(name: str):
    """The historical constants, read from the registry when asked for."""
    if name == "GAIN_MARGIN_FLOOR":
        return floors()["gain_margin"]
    if name == "PHASE_MARGIN_FLOOR_DEG":
        return floors()["phase_margin_deg"]
    if name == "STABILITY_FLOOR":
        return stability_floor()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def robustness(margins) -> dict:
    """{"gain_margin", "phase_margin_deg" (unsigned, controllers.margins),
    "phase_margin_signed_deg" (python-control's stability_margins sign), "floors", "meets",
    "why"} of controllers.margins' Margins (JSON-ready: inf as None)."""
    gm, pm = float(margins.gain_margin), float(margins.phase_margin_deg)
    f = floors()
    # a gain margin below 1 means the gains must shrink to reach -1: as far from it as 1/gm
    gm_distance = gm if gm >= 1 else 1 / gm if gm > 0 else 0.0
    short = []
    if gm_distance < f["gain_margin"]:
        short.append(f"gain margin {gm:.3g} (a {100 * abs(gm - 1):.3g} % change of the gains "
                     f"or of the device's impedance reaches instability; floor "
                     f"{f['gain_margin']:g}, design.gain_margin_min)")
    if pm < f["phase_margin_deg"]:
        short.append(f"phase margin {pm:.3g} deg (floor {f['phase_margin_deg']:g} deg, "
                     f"design.phase_margin_min_deg)")
    if not margins.stable:
        short.insert(0, "the closed loop is unstable")
    finite = (lambda v: v if math.isfinite(v) else None)
    signed = getattr(margins, "phase_margin_signed_deg", pm)
    return {"gain_margin": finite(gm), "phase_margin_deg": finite(pm),
            "phase_margin_signed_deg": finite(float(signed)), "floors": f,
            "meets": not short and bool(margins.stable),
            "why": "; ".join(short) if short else "meets both floors"}


def share_explained(plant, wave, pto: str, predicted_W: float, name: str,
                    robust: bool = False) -> dict:
    """Why a linear law absorbs the share of the complex-conjugate bound it does, in linear
    theory: the bound with every force allowed, the bound inside the envelope, and the law's
    prediction; the gap between the last two is what a fixed damper (and spring) cannot do
    across the sea's frequencies (robust: and within the robustness floors), the gap between
    the first two what the envelope forbids. name: the registered linear law (its `tuned`
    says whether it has a spring, its `floors` whether robust tuning bound it)."""
    from mbcontrol.analysis import envelope_bound
    b = envelope_bound(plant, wave, pto)
    cc, inside = b["unconstrained_W"], b["bound_W"]
    out = {"complex_conjugate_W": cc, "envelope_bound_W": inside, "predicted_W": predicted_W,
           "binding": b["binding"]}
    if not cc or inside is None or predicted_W is None:
        out["why"] = "no bound inside the envelope (the sea alone leaves it)"
        return out
    if math.isinf(cc):          # components where the data give the PTO no damping
        out["why"] = "the complex-conjugate bound of this wave is unbounded (see the bounds)"
        if math.isfinite(inside) and inside > 0:
            out["why"] += (f"; the law predicts {100 * predicted_W / inside:.3g} % of the "
                           f"bound inside the linear model's envelope ({inside / 1e3:.4g} kW"
                           + (f", {', '.join(b['binding'])} binding" if b["binding"] else "")
                           + ")")
        return out
    from . import REGISTRY
    cls = REGISTRY[name]
    spring = "stiffness" in cls.tuned
    law = "a damper and spring" if spring else "a damper"
    parts = [f"the law predicts {100 * predicted_W / cc:.3g} % of the complex-conjugate bound"]
    if b["binding"]:
        parts.append(f"the envelope ({', '.join(b['binding'])}) caps any force at "
                     f"{100 * inside / cc:.3g} %")
    gap = 100 * (inside - predicted_W) / cc
    if gap > 0.5:
        parts.append(f"the other {gap:.3g} points are what {law} fixed for the sea"
                     + (" within the robustness floors (--aggressive lifts them)"
                        if robust and cls.floors else "")
                     + " cannot do: it matches the device's impedance at one frequency at most"
                     + ("" if spring else " and absorbs no reactive power"))
    out["why"] = "; ".join(parts)
    return out
