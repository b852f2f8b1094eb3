"""Safe by default, and one tuner (issue 58): `design` and `export` tune the same law with the
same numbers (studies.design.tune on cli.design.design_wave's sea), within the margins of
`mbcontrol defaults` (gain 2, phase 30 deg) unless --aggressive. Before, export tuned a sea on
its 200 s check spacing and design on 600 s: sphere, Hs 2 m, Tp 8 s, damping 224 against
243 kN s/m; and the default reactive law had a gain margin of 1.62 (sphere, H 2 m, T 8 s)."""
import json

import pytest

from mbcontrol import build_plant
from mbcontrol.cli import build_parser, main
from mbcontrol.cli.commands import _wave
from mbcontrol.cli.export import _controller, _robustness

WAVES = {"regular": ["--wave", "regular", "--height", "2", "--period", "8"],
         "jonswap": ["--wave", "jonswap", "--hs", "2", "--tp", "8"]}


@pytest.fixture(scope="module")
def plant():
    return build_plant("sphere")


def _design(capsys, wave, *extra):
    assert main(["design", "sphere", *WAVES[wave], "--controller", "reactive", "--duration",
                 "100", "--bounds", "off", "--json", *extra]) == 0
    return json.loads(capsys.readouterr().out)


def _exported(plant, wave, tmp_path, *extra):
    """The law `mbcontrol export` would ship, as run_export builds it (no C compiled)."""
    args = build_parser().parse_args(["export", "sphere", *WAVES[wave], "--controller",
                                      "reactive", "--duration", "100", "--out",
                                      str(tmp_path), *extra])
    check = _wave(args, plant, args.duration)
    controller, origin = _controller(args, plant, check)
    return controller, _robustness(args, plant, controller, origin)


@pytest.mark.parametrize("wave", ["regular", "jonswap"])
def test_design_and_export_give_the_same_law_within_the_margins(plant, wave, capsys, tmp_path):
    designed = _design(capsys, wave)
    controller, robustness = _exported(plant, wave, tmp_path)
    for key in ("damping", "stiffness"):
        assert getattr(controller, key) == pytest.approx(designed["parameters"][key],
                                                         rel=1e-12), key
    margins = designed["margins"]
    assert margins["stable"] and margins["gain_margin"] >= 2.0
    assert margins["phase_margin_deg"] >= 30.0
    assert designed["tuner"]["robust"] is True and designed["tuner"]["robustness"]["meets"]
    assert robustness["pto"]["meets"]
    # export's check is the design's: the same figures from the same law
    assert robustness["pto"]["gain_margin"] == pytest.approx(margins["gain_margin"], rel=1e-9)


def test_aggressive_is_the_unconstrained_optimum_and_export_refuses_it(plant, capsys, tmp_path):
    designed = _design(capsys, "regular", "--aggressive")
    # complex-conjugate control at T = 8 s within the force limit: below both floors
    assert designed["tuner"]["robust"] is False
    assert designed["margins"]["gain_margin"] < 2.0
    assert not designed["tuner"]["robustness"]["meets"]
    controller, robustness = _exported(plant, "regular", tmp_path, "--aggressive")
    assert controller.damping == pytest.approx(designed["parameters"]["damping"], rel=1e-12)
    assert not robustness["pto"]["meets"]
    assert "below the robustness floors" in capsys.readouterr().err
    law = [f"damping={controller.damping!r}", f"stiffness={controller.stiffness!r}"]
    code = main(["export", "sphere", *WAVES["regular"], "--controller", "reactive",
                 "--set", law[0], "--set", law[1], "--out", str(tmp_path), "--no-check"])
    err = capsys.readouterr().err
    assert code != 0 and "gain margin 2, phase margin 30 deg" in err and "--aggressive" in err
    assert not (tmp_path / "c").exists()          # refused before anything is written


def test_a_passive_damper_still_passes(plant, capsys, tmp_path):
    """A damper on a passive device: Re L >= 0, so no crossing of the negative real axis."""
    assert main(["design", "sphere", *WAVES["regular"], "--controller", "passive",
                 "--duration", "60", "--bounds", "off", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["margins"]["gain_margin"] is None                 # inf
    assert d["margins"]["phase_margin_deg"] >= 90 and d["tuner"]["robustness"]["meets"]
    args = build_parser().parse_args(["export", "sphere", *WAVES["regular"], "--controller",
                                      "passive", "--set", "damping=3e6", "--out",
                                      str(tmp_path)])
    controller, origin = _controller(args, plant, None)
    assert _robustness(args, plant, controller, origin)["pto"]["meets"]


def test_a_sea_is_tuned_on_the_designs_spacing_whatever_the_check_length(plant, tmp_path):
    """Without --duration export checks 200 s but tunes on design's 600 s spacing: the law is
    the one design's own call (studies.design.tune on cli.design.design_wave) returns."""
    from mbcontrol.cli.design import design_wave
    from mbcontrol.studies.design import tune
    args = build_parser().parse_args(["design", "sphere", *WAVES["jonswap"], "--controller",
                                      "reactive"])
    wave, repeat = design_wave(args, plant)
    assert repeat == 600.0
    parameters, *_ = tune(plant, wave, "reactive", plant.scene.ptos[0], True, None, [])
    export_args = build_parser().parse_args(["export", "sphere", *WAVES["jonswap"],
                                             "--controller", "reactive", "--out",
                                             str(tmp_path)])
    controller, _ = _controller(export_args, plant, _wave(export_args, plant, 200.0))
    assert controller.damping == pytest.approx(parameters["damping"], rel=1e-12)
    assert controller.stiffness == pytest.approx(parameters["stiffness"], rel=1e-12)


def test_design_draws_the_loop_it_reports(capsys, tmp_path):
    bode, nyquist = tmp_path / "bode.png", tmp_path / "nyquist.png"
    d = _design(capsys, "regular", "--bode", str(bode), "--nyquist", str(nyquist))
    assert d["figures"] == {"bode": str(bode), "nyquist": str(nyquist)}
    assert bode.stat().st_size > 10_000 and nyquist.stat().st_size > 10_000
    # the report carries python-control's signed phase margin beside mbcontrol's unsigned one
    m = d["margins"]
    assert abs(m["phase_margin_signed_deg"]) == pytest.approx(m["phase_margin_deg"], rel=1e-9)
