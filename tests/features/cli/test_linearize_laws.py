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


def test_no_pto_law_drops_exactly_the_scene_damper(capsys):
    """--no-pto-law: the PTO's own scene law zeroed. The open loop's impedance from the PTO
    force to its velocity, 1 / G(i omega), changes by exactly the scene's 2e5 N s/m at every
    frequency (the damper is in parallel with the rest of the device)."""
    import numpy as np

    from mbcontrol import build_plant
    from mbcontrol.analysis import linearize
    free = _linearize(capsys, "--no-pto-law")
    assert free["pto_laws"] == {"pto": {"damping": 0.0, "stiffness": 0.0}}
    assert free["pto_laws_dropped"] is True
    assert free["poles"] == _linearize(capsys, "--param", "pto__damping=0")["poles"]
    kept = _linearize(capsys, "--no-pto-law", "--param", "pto__damping=5e4")
    assert kept["pto_laws"]["pto"]["damping"] == 5e4          # --param still sets it
    plant = build_plant("sphere")
    omega = np.array([0.3, 0.8, 1.5, 3.0])
    impedance = []
    for params in (None, {"pto__damping": 0.0, "pto__stiffness": 0.0}):
        G = linearize(plant, params=params, inputs=["u__pto"], outputs=["pto__velocity"])
        impedance.append(1 / np.array([complex(np.asarray(G(1j * w)).ravel()[0])
                                       for w in omega]))
    assert np.allclose(impedance[0] - impedance[1], 2.0e5, rtol=1e-9, atol=0)
    assert main(["linearize", "sphere", "--no-pto-law"]) == 0
    assert "PTO laws are left out (--no-pto-law)" in capsys.readouterr().out
