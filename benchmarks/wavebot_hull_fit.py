"""WecOptTool's own WaveBot hull in heave, a device nobody tuned a radiation fit for (issue 37):
the fit judged by the response on first use, and its time-domain heave against the frequency-domain
solution over 0.2-1.5 Hz. Not a CI test: WecOptTool (and gmsh) make the mesh, in the venv of
benchmarks/wecopttool_electrical.py (out/wecopttool-venv, installed on first use).

The scene: WecOptTool's mesh (mesh_size_factor 0.5, as its tutorial 1), 50 frequencies 0.05-2.5 Hz,
10 cm panels, heave on a prismatic joint, a PTO with no damping of its own (the fit sees the PTO
free either way), mass rho x the mesh's immersed volume (the PTO's "balance" preload takes the last
gram). The time domain starts on the fitted model's periodic solution and runs 14 periods of 200
RK4 steps in 5 cm waves (mbcontrol.analysis.regular_wave_amplitudes); the frequency domain uses the
BEM data at each frequency directly.

Run: python benchmarks/wavebot_hull_fit.py [--out out/bench/wavebot_hull] [--json]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

MESH = ("import meshio, sys, wecopttool as wot\n"
        "meshio.write(sys.argv[1], wot.geom.WaveBot().mesh(mesh_size_factor=0.5))\n")
SCENE = '''name = "wavebot_hull"
description = "WecOptTool's tutorial-1 WaveBot hull in heave: its own mesh, a free PTO"

[water]
rho = 1025.0
g = 9.81

[hydro]
omega = { min = 0.3141592653589793, max = 15.707963267948966, n = 50 }
panel_size = "10 cm"
dofs = ["Heave"]

[[body]]
name = "wavebot"
mass = 874.4                      # kg: rho x the mesh's immersed volume, to 0.1 kg
inertia = [100.0, 100.0, 100.0]
cog = [0.0, 0.0, 0.0]
geometry = { type = "mesh", file = "wavebot.stl" }

[[joint]]
name = "heave"
type = "prismatic"
parent = "ground"
child = "wavebot"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]

[[pto]]
name = "pto"
joint = "heave"
preload = "balance"
'''


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(ROOT / "out" / "bench" / "wavebot_hull"))
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    args = parser.parse_args(argv)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    from wecopttool_electrical import peer_python
    if not (out / "wavebot.stl").exists():
        subprocess.run([str(peer_python(out)), "-c", MESH, str(out / "wavebot.stl")], check=True,
                       capture_output=True)
    (out / "wavebot_hull.toml").write_text(SCENE)

    from mbcontrol.analysis import frequency_domain_response, linearize, regular_wave_amplitudes
    from mbcontrol.hydro.fit.radiation import RadiationFitWarning
    from mbcontrol.plant import build_plant
    started = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RadiationFitWarning)
        plant = build_plant(str(out / "wavebot_hull.toml"))
    seconds = time.perf_counter() - started
    rep = plant.hydro.radiation.report
    omegas = 2 * np.pi * np.geomspace(0.2, 1.5, 12)
    td = regular_wave_amplitudes(plant, linearize(plant), omegas, ["heave"], height=0.05)[:, 0]
    fd = np.abs(frequency_domain_response(plant, omegas, outputs=["heave"]))[:, 0]
    result = {"states": rep["n_states"], "tol": rep["tol"], "response_error": rep["response_error"],
              "response_worst": rep["response_worst"], "kernel_band_error": rep["band_error"],
              "kernel_rms_error": rep["rms_error"], "first_use_s": seconds,
              "warnings": [str(c.message) for c in caught if issubclass(c.category, RadiationFitWarning)],
              "frequency_hz": (omegas / 2 / np.pi).tolist(), "td_over_fd_minus_1": (td / fd - 1).tolist(),
              "worst_td_fd": float(np.max(np.abs(td / fd - 1)))}
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"WaveBot hull (WecOptTool mesh), first use {seconds:.0f} s (BEM included unless cached): "
          f"{rep['n_states']} states, response error {rep['response_error']:.2%} (tol {rep['tol']:.0%}), "
          f"kernel worst {rep['band_error']:.1%}, RMS {rep['rms_error']:.2%}; "
          f"{len(result['warnings'])} fit warnings")
    for f, e in zip(result["frequency_hz"], result["td_over_fd_minus_1"]):
        print(f"  {f:5.3f} Hz  heave TD / FD - 1 = {e:+.3%}")
    print(f"  worst {result['worst_td_fd']:.3%}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
