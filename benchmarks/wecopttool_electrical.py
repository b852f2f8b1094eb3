"""Side by side with WecOptTool 3.3 on its tutorial-1 WaveBot: mechanical and electrical
optimal power, unconstrained and with its 750 N force limit, in its regular wave (amplitude
0.0625 m at 0.3 Hz). Not a CI test: WecOptTool (and gmsh for its WaveBot mesh) install into a
venv of their own, out/wecopttool-venv, on first use.

Same case on both sides: WecOptTool meshes the hull and solves it with Capytaine; mbcontrol
reads that mesh (STL) and solves it with its own Capytaine run at the same 50 frequencies
(0.05..2.5 Hz), the same mass (rho x immersed volume) and the same drivetrain (gear 12,
6.7 N m/A x sqrt(3/2), 0.5 ohm, 2 kg m^2, 1 N m s/rad). WecOptTool's PTO force is the force on
the hull (the machine's less the drivetrain's inertia and friction forces): its 750 N is
compared with mbcontrol's electrical_bound(force_on="wec"); the machine-force figure is
printed beside it. The WecOptTool force may use every multiple of 0.05 Hz; mbcontrol's every
multiple of the wave's 0.3 Hz up to 2.5 Hz (the others carry no excitation).

Run: python benchmarks/wecopttool_electrical.py [--out out/bench/wecopttool]
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
AMPLITUDE, FREQUENCY, F1, NFREQ, FORCE_MAX = 0.0625, 0.3, 0.05, 50, 750.0
DRIVE = dict(gear=12.0, kt=6.7, R=0.5, J=2.0, b=1.0)

PEER = textwrap.dedent('''
    import json, sys
    import jax.numpy as jnp
    import meshio
    import numpy as np
    import capytaine as cpy
    import wecopttool as wot
    from capytaine.io.meshio import load_from_meshio
    out, a, f, f1, nfreq, f_max = sys.argv[1], *map(float, sys.argv[2:4]), float(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
    d = json.loads(sys.argv[7])
    mesh = wot.geom.WaveBot().mesh(mesh_size_factor=0.5)
    meshio.write(f"{out}/wavebot.stl", mesh)
    hull = load_from_meshio(mesh, "WaveBot")
    fb = cpy.FloatingBody(mesh=hull, lid_mesh=hull.generate_lid(-2e-2), name="WaveBot")
    fb.add_translation_dof(name="Heave")
    fb.center_of_mass = [0, 0, 0]
    fb.rotation_center = fb.center_of_mass
    bem = wot.run_bem(fb, wot.frequency(f1, nfreq, False))
    omega = bem.omega.values
    z11 = -d["gear"] ** 2 * (1j * omega * d["J"] + d["b"])
    off = -np.sqrt(1.5) * d["kt"] * d["gear"] * np.ones(omega.shape) + 0j
    impedance = np.array([[z11, off], [off, d["R"] + 0j * omega]])
    waves = wot.waves.regular_wave(f1, nfreq, f, a, 30.0, 0.0)
    results = {"mass_kg": float(bem.inertia_matrix.values.ravel()[0]),
               "stiffness_N_per_m": float(bem.hydrostatic_stiffness.values.ravel()[0])}
    for label, limit, electrical in (("mechanical", None, False), ("electrical", None, True),
                                     ("mechanical_limited", f_max, False),
                                     ("electrical_limited", f_max, True)):
        pto = wot.pto.PTO(1, np.eye(1), None, impedance if electrical else None, None, ["PTO"])
        constraints = []
        if limit is not None:
            def bound(wec, x_wec, x_opt, wave, pto=pto, limit=limit):
                return limit - jnp.abs(pto.force_on_wec(wec, x_wec, x_opt, wave, 4).flatten())
            constraints = [{"type": "ineq", "fun": bound}]
        wec = wot.WEC.from_bem(bem, constraints=constraints, f_add={"PTO": pto.force_on_wec})
        res = wec.solve(waves, pto.average_power, 2 * nfreq, scale_x_wec=1e1, scale_x_opt=1e-3,
                        scale_obj=1e-2, optim_options={"maxiter": 1000})[0]
        x_wec, x_opt = wec.decompose_state(res.x)
        results[label] = {"power_W": -float(res.fun), "success": bool(res.success),
                          "mechanical_W": -float(pto.mechanical_average_power(wec, x_wec, x_opt, waves))}
    print(json.dumps(results))
''')

SCENE = '''name = "wavebot"
description = "WecOptTool's tutorial-1 WaveBot in heave: its mesh, mass and electrical PTO"

[water]
rho = 1025.0
g = 9.81

[hydro]
omega = {{ min = {w0!r}, max = {w1!r}, n = {n} }}
panel_size = "10 cm"
dofs = ["Heave"]

[[body]]
name = "wavebot"
mass = {mass!r}
inertia = [100.0, 100.0, 100.0]
cog = [0.0, 0.0, 0.0]
geometry = {{ type = "mesh", file = "wavebot.stl" }}

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
force_max = {force_max!r}
'''
DRIVETRAIN = '''
[pto.drivetrain]
gear_ratio = {gear!r}
torque_constant = {kt!r}
winding_resistance = {R!r}
inertia = {J!r}
friction = {b!r}
phases = 3
'''


def peer_python(out: Path) -> Path:
    venv = ROOT / "out" / "wecopttool-venv"
    python = venv / "bin" / "python"
    if not python.exists():
        print(f"[wecopttool] installing WecOptTool 3.3.0 into {venv} (once)", flush=True)
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "--quiet",
                        "wecopttool[geometry]==3.3.0"], check=True)
    return python


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(ROOT / "out" / "bench" / "wecopttool"))
    args = parser.parse_args(argv)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    done = subprocess.run([str(peer_python(out)), "-c", PEER, str(out), str(AMPLITUDE),
                           str(FREQUENCY), str(F1), str(NFREQ), str(FORCE_MAX), json.dumps(DRIVE)],
                          capture_output=True, text=True)
    if done.returncode:
        print(done.stderr[-3000:], file=sys.stderr)
        return 1
    peer = json.loads(done.stdout.strip().splitlines()[-1])
    peer_s = time.perf_counter() - start

    from mbcontrol import build_plant, waves
    from mbcontrol.analysis import complex_conjugate_bound, pseudo_spectral_bound
    from mbcontrol.analysis.electrical import electrical_bound
    start = time.perf_counter()
    omega = (2 * math.pi * F1, 2 * math.pi * F1 * NFREQ)
    text = SCENE.format(w0=omega[0], w1=omega[1], n=NFREQ, mass=peer["mass_kg"],
                        force_max=FORCE_MAX)
    (out / "wavebot_ideal.toml").write_text(text)
    (out / "wavebot.toml").write_text(text + DRIVETRAIN.format(**DRIVE))
    wave = waves.regular(2 * AMPLITUDE, 1 / FREQUENCY)      # WecOptTool's amplitude is ours/2
    ideal, electric = build_plant(out / "wavebot_ideal.toml"), build_plant(out / "wavebot.toml")
    harmonics = dict(omega_max=omega[1])
    ours = {
        "mechanical": complex_conjugate_bound(ideal, wave).power,
        "mechanical_limited": pseudo_spectral_bound(ideal, wave, force_max=FORCE_MAX,
                                                    **harmonics).mean_power,
        "electrical": electrical_bound(electric, wave, **harmonics).electrical_W,
        "electrical_limited": electrical_bound(electric, wave, force_max=FORCE_MAX,
                                               force_on="wec", **harmonics).electrical_W,
        "electrical_limited_machine_force": electrical_bound(
            electric, wave, force_max=FORCE_MAX, **harmonics).electrical_W,
    }
    ours_s = time.perf_counter() - start
    stiffness = float(ideal.hydro.data.hydrostatic_stiffness.sel(
        radiating_dof="wavebot__Heave", influenced_dof="wavebot__Heave"))
    rows = []
    print(f"WaveBot, regular wave a = {AMPLITUDE} m at {FREQUENCY} Hz; heave stiffness "
          f"WecOptTool {peer['stiffness_N_per_m']:.1f} N/m, mbcontrol {stiffness:.1f} N/m")
    print(f"{'optimum':<34} {'WecOptTool':>11} {'mbcontrol':>11} {'difference':>11}")
    for key, label in (("mechanical", "mechanical, no limit"),
                       ("mechanical_limited", f"mechanical, |F| <= {FORCE_MAX:.0f} N"),
                       ("electrical", "electrical, no limit"),
                       ("electrical_limited", f"electrical, |F on hull| <= {FORCE_MAX:.0f} N")):
        diff = 100 * (ours[key] / peer[key]["power_W"] - 1)
        rows.append({"optimum": key, "wecopttool_W": peer[key]["power_W"], "mbcontrol_W": ours[key],
                     "difference_pct": diff, "wecopttool_success": peer[key]["success"]})
        print(f"{label:<34} {peer[key]['power_W']:>9.3f} W {ours[key]:>9.3f} W {diff:>+10.3f} %")
    print(f"mbcontrol with the machine's force limited instead: "
          f"{ours['electrical_limited_machine_force']:.3f} W")
    print(f"wall time (BEM included): WecOptTool {peer_s:.1f} s, mbcontrol {ours_s:.1f} s")
    (out / "wecopttool_electrical.json").write_text(json.dumps(
        {"rows": rows, "peer": peer, "mbcontrol": ours, "wall_s": {"wecopttool": peer_s,
                                                                   "mbcontrol": ours_s}}, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
