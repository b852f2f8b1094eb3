"""The designed loop's figures (controllers.loop_plots, `design --bode --nyquist`) mark
python-control's numbers: loop_marks against control.stability_margins on the same L(s), for
the sphere's reactive laws (within the margins, and the aggressive optimum) and a damper."""
import math

import control
import numpy as np
import pytest

from mbcontrol import build_plant
from mbcontrol.controllers import loop_bode, loop_margins, loop_marks, loop_nyquist

LAWS = {"within the margins": {"damping": 274950.0, "stiffness": -347405.0},
        "aggressive": {"damping": 144541.0, "stiffness": -474362.0},
        "damper": {"damping": 2e5, "stiffness": 0.0}}


@pytest.fixture(scope="module")
def plant():
    return build_plant("sphere")


@pytest.mark.parametrize("law", list(LAWS))
def test_the_marks_are_python_controls_stability_margins(plant, law):
    margins = loop_margins(plant, LAWS[law])
    marks = loop_marks(margins)
    gm, pm, sm, wpc, wgc, wsm = control.stability_margins(margins.loop)
    assert marks["gain_margin"] == pytest.approx(gm, rel=1e-9)
    assert marks["phase_margin_deg"] == pytest.approx(pm, rel=1e-9)     # signed
    assert marks["gain_crossover_rad_s"] == pytest.approx(wgc, rel=1e-9)
    assert abs(margins.phase_margin_deg) == pytest.approx(abs(pm), rel=1e-9)  # mbcontrol's
    if math.isfinite(gm):
        assert marks["phase_crossover_rad_s"] == pytest.approx(wpc, abs=1e-9)
        assert marks["gain_margin_dB"] == pytest.approx(20 * np.log10(gm), rel=1e-9)
    if math.isfinite(sm):       # python-control's search looks at interior minima only
        assert marks["stability_margin"] == pytest.approx(sm, rel=1e-9)
        assert marks["stability_margin_rad_s"] == pytest.approx(wsm, rel=1e-6)
    else:                       # a damper: the least |1 + L| = 1, at omega = 0 and infinity
        assert marks["stability_margin"] == pytest.approx(1.0, abs=1e-9)
    if law == "aggressive":     # stable, yet python-control's sign reads negative
        assert margins.stable and pm < 0 < margins.phase_margin_deg


def test_the_figures_carry_the_marks_and_units(plant, tmp_path):
    margins = loop_margins(plant, LAWS["aggressive"])
    m = loop_marks(margins)
    bode = loop_bode(margins, path=tmp_path / "bode.png")
    nyquist = loop_nyquist(margins, path=tmp_path / "nyquist.png")
    assert (tmp_path / "bode.png").stat().st_size > 0
    assert (tmp_path / "nyquist.png").stat().st_size > 0
    texts = [t.get_text() for ax in bode.axes for t in ax.texts]
    labels = [ax.get_xlabel() + ax.get_ylabel() for ax in bode.axes]
    assert any(f"GM = {m['gain_margin']:.3g}" in t for t in texts)
    assert any(f"PM = {m['phase_margin_deg']:+.3g}°" in t for t in texts)
    assert "ω (rad/s)" in labels[1] and "(dB)" in labels[0] and "(deg)" in labels[1]
    legend = [t.get_text() for t in nyquist.axes[1].get_legend().get_texts()]
    assert any(f"min |1 + L| = {m['stability_margin']:.3g}" in t for t in legend)
