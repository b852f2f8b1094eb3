"""Whether a designed linear law can be deployed, and why it reaches the share of the bound
it does: robustness floors on its stability margins, and its power set against the bounds
with and without the linear model's envelope (analysis.envelope).

Floors (controllers.margins' quantities): a gain margin of GAIN_MARGIN_FLOOR (the gains, or
the device's impedance they were tuned to, may be off by that factor) and a phase margin of
PHASE_MARGIN_FLOOR_DEG, the textbook 6 dB and 30 deg. A design below them is flagged, not
refused: complex-conjugate control is near its edge by construction (it cancels the device's
reactance), so a user decides with the figures in hand, or asks for a robust design
(`robust=True`, `--robust`): the reactive tuner then keeps min |1 + L| >= STABILITY_FLOOR,
which meets both floors (rm3, Hs 2 m, Tp 10 s: gain margin 1.03 -> 2.08, phase margin 12 ->
60 deg, 2 % less power predicted). No slowest-pole floor: on rm3 a mode
no PTO force moves decays at 0.002 1/s whatever the law (controllers.impedance.margin_function
for any damping), so such a floor says nothing about the law.
"""
from __future__ import annotations

import math

GAIN_MARGIN_FLOOR = 2.0
PHASE_MARGIN_FLOOR_DEG = 30.0
# what a robust tuner (reactive_tuning(robust=True), design --robust) keeps: the Nyquist curve
# at least s from -1 everywhere, which guarantees a gain margin of 1 / (1 - s) and a phase
# margin of 2 asin(s / 2): with s = 0.52, 2.08 and 30.1 deg, both floors with a little room
STABILITY_FLOOR = 0.52


def robustness(margins) -> dict:
    """{"gain_margin", "phase_margin_deg", "floors", "meets", "why"} of controllers.margins'
    Margins (JSON-ready: inf as None)."""
    gm, pm = float(margins.gain_margin), float(margins.phase_margin_deg)
    # a gain margin below 1 means the gains must shrink to reach -1: as far from it as 1/gm
    gm_distance = gm if gm >= 1 else 1 / gm if gm > 0 else 0.0
    short = []
    if gm_distance < GAIN_MARGIN_FLOOR:
        short.append(f"gain margin {gm:.3g} (a {100 * abs(gm - 1):.3g} % change of the gains "
                     f"or of the device's impedance reaches instability; floor "
                     f"{GAIN_MARGIN_FLOOR:g})")
    if pm < PHASE_MARGIN_FLOOR_DEG:
        short.append(f"phase margin {pm:.3g} deg (floor {PHASE_MARGIN_FLOOR_DEG:g} deg)")
    finite = (lambda v: v if math.isfinite(v) else None)
    return {"gain_margin": finite(gm), "phase_margin_deg": finite(pm),
            "floors": {"gain_margin": GAIN_MARGIN_FLOOR,
                       "phase_margin_deg": PHASE_MARGIN_FLOOR_DEG},
            "meets": not short and bool(margins.stable),
            "why": "; ".join(short) if short else "meets both floors"}


def share_explained(plant, wave, pto: str, predicted_W: float, name: str) -> dict:
    """Why a linear law absorbs the share of the complex-conjugate bound it does, in linear
    theory: the bound with every force allowed, the bound inside the envelope, and the law's
    prediction; the gap between the last two is what a fixed damper (and spring) cannot do
    across the sea's frequencies, the gap between the first two what the envelope forbids."""
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
    law = "a damper" if name == "passive" else "a damper and spring"
    parts = [f"the law predicts {100 * predicted_W / cc:.3g} % of the complex-conjugate bound"]
    if b["binding"]:
        parts.append(f"the envelope ({', '.join(b['binding'])}) caps any force at "
                     f"{100 * inside / cc:.3g} %")
    gap = 100 * (inside - predicted_W) / cc
    if gap > 0.5:
        parts.append(f"the other {gap:.3g} points are what {law} fixed for the sea cannot do: "
                     f"it matches the device's impedance at one frequency at most"
                     + (" and absorbs no reactive power" if name == "passive" else ""))
    out["why"] = "; ".join(parts)
    return out
