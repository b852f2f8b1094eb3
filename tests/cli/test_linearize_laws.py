"""`mbcontrol linearize` says which PTO laws of the scene its model includes, and --param
drops them (issue 58: it silently included the scene's damper). The sphere's scene sets a
2e5 N s/m damper: with it the slowest pole decays at 0.49 1/s, without it at 0.14 1/s
(radiation damping alone), so the model changes as the statement says."""
import json

from mbcontrol.cli import main


def _linearize(capsys, *extra):
    assert main(["linearize", "sphere", "--json", *extra]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_scene_damper_is_stated_and_can_be_dropped(capsys):
    damped = _linearize(capsys)
    assert damped["pto_laws"] == {"pto": {"damping": 2.0e5, "stiffness": 0.0}}
    free = _linearize(capsys, "--param", "pto__damping=0")
    assert free["pto_laws"] == {"pto": {"damping": 0.0, "stiffness": 0.0}}
    slowest = [max(p[0] for p in info["poles"]) for info in (damped, free)]
    assert slowest[0] < 2 * slowest[1] < 0                 # the damper is what it says
    assert main(["linearize", "sphere"]) == 0
    assert "includes PTO 'pto' as the scene sets it: damping 200000" in capsys.readouterr().out
