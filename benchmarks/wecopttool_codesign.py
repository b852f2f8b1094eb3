"""Side by side with WecOptTool 3.3 on its tutorial 1 part 3 co-design study: the WaveBot's
keel radius r2 at constant displaced volume (h2 follows r2), and for each r2 the most
electrical power under a 750 N limit on the force on the hull, in a regular wave of amplitude
0.0625 m at 0.3 Hz. Not a CI test: WecOptTool installs into out/wecopttool-venv on first use
(benchmarks/wecopttool_electrical.py's peer_python).

WecOptTool runs part 3 as its tutorial does (examples/tutorial_1_WaveBot.ipynb, design_obj_fun):
WaveBot(r2=r2, h2=h2_from_r2(r2)) meshed by gmsh at mesh_size_factor 0.5, no lid, mass rho x
the immersed mesh volume, its drivetrain two-port, pto.force limited at 4 substeps,
pto.average_power, nstate_opt = 2 x 50. The frequencies are part 1's global `freq` and
`waves` (f1 = 0.3 Hz, nfreq = 10: 0.3..3.0 Hz): design_obj_fun sets f1 = 0.05, nfreq = 50 but
never uses them for run_bem (only nstate_opt = 100; the unstructured controller reads the
first 20). `--peer-grid 0.05 50` runs the grid it sets instead.

mbcontrol: models/wavebot.toml at each r2 (its own revolution mesh, Capytaine on first use,
cached by content), electrical_bound with the force on the hull limited (the scene's
force_max_on = "hull") and the force on every multiple of 0.3 Hz up to the top of WecOptTool's
grid (3.0 Hz: its 10 frequencies; 2.5 Hz with --peer-grid 0.05 50), which the scene's holds.

Run: python benchmarks/wecopttool_codesign.py [--out out/bench/wecopttool_codesign]
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

sys.path.insert(0, str(Path(__file__).resolve().parent))
from wecopttool_electrical import peer_python  # noqa: E402  (one install for both benchmarks)

ROOT = Path(__file__).resolve().parents[1]
AMPLITUDE, FREQUENCY, FORCE_MAX = 0.0625, 0.3, 750.0
R2 = [0.05, 0.168446, 0.286891, 0.405337, 0.523783, 0.642229, 0.760674, 0.87912]  # np.linspace(0.05, 0.88 * 0.999, 8)

# tutorial 1 part 3, cell for cell (design_obj_fun), one JSON line per r2
PEER = textwrap.dedent('''
    import json, sys, time
    import jax.numpy as jnp
    import numpy as np
    import capytaine as cpy
    import wecopttool as wot
    wot.set_loglevel("error")
    r2s, f1, nfreq = json.loads(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
    amplitude, wavefreq, f_max = float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6])
    r1, r2_0, h2_0 = 0.88, 0.35, 0.37
    V0 = 1/3*np.pi*h2_0*(r1**2+r2_0**2+(r1*r2_0))
    def h2_from_r2(r2, V=V0, r1=r1):
        return V/(1/3*np.pi*(r1**2+r2**2+(r1*r2)))
    freq = wot.frequency(f1, nfreq, False)
    waves = wot.waves.regular_wave(f1, nfreq, wavefreq, amplitude, 30, 0)
    for r2 in r2s:
        t0 = time.perf_counter()
        h2 = h2_from_r2(r2)
        fb = cpy.FloatingBody.from_meshio(wot.geom.WaveBot(r2=r2, h2=h2).mesh(mesh_size_factor=0.5),
                                          name="WaveBot")
        fb.add_translation_dof(name="Heave")
        bem_data = wot.check_radiation_damping(wot.add_linear_friction(wot.run_bem(fb, freq), friction=None))
        omega = bem_data.omega.values
        drivetrain_impedance = 1j*omega*2.0 + 1.0          # J = 2 kg m^2, b = 1 N m s/rad, no spring
        off_diag = np.sqrt(3.0/2.0)*6.7*12.0               # kt' x gear
        imp = np.array([[-12.0**2*drivetrain_impedance, -(off_diag+0j)*np.ones(omega.shape)],
                        [-(off_diag+0j)*np.ones(omega.shape), 0.5 + 0j*omega]])
        pto = wot.pto.PTO(1, np.eye(1), None, imp, None, ["PTO_Heave"])
        def const_f_pto(wec, x_wec, x_opt, wave):
            return f_max - jnp.abs(pto.force(wec, x_wec, x_opt, wave, 4).flatten())
        wec = wot.WEC.from_bem(bem_data, constraints=[{"type": "ineq", "fun": const_f_pto}],
                               friction=None, f_add={"PTO": pto.force_on_wec})
        res = wec.solve(waves, pto.average_power, 2*50, scale_x_wec=1e1, scale_x_opt=1e-3,
                        scale_obj=1e-2)[0]
        k = int(np.argmin(np.abs(omega - 2*np.pi*wavefreq)))
        print(json.dumps({"r2": r2, "h2": h2, "power_W": -float(res.fun), "success": bool(res.success),
                          "mass_kg": float(bem_data.inertia_matrix.values.ravel()[0]),
                          "stiffness_N_per_m": float(bem_data.hydrostatic_stiffness.values.ravel()[0]),
                          "added_mass_kg": float(bem_data.added_mass.values.ravel()[k]),
                          "damping_N_s_per_m": float(bem_data.radiation_damping.values.ravel()[k]),
                          "panels": int(fb.mesh.nb_faces), "wall_s": time.perf_counter() - t0}),
              flush=True)
''')


def run_peer(r2s, f1: float, nfreq: int) -> list[dict]:
    """WecOptTool's rows (tutorial 1 part 3 at each r2), or SystemExit with its stderr."""
    done = subprocess.run([str(peer_python(ROOT / "out")), "-c", PEER, json.dumps(r2s), str(f1),
                           str(nfreq), str(AMPLITUDE), str(FREQUENCY), str(FORCE_MAX)],
                          capture_output=True, text=True)
    rows = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode or len(rows) != len(r2s):
        print(done.stderr[-3000:], file=sys.stderr)
        raise SystemExit(1)
    return rows


def run_ours(r2s, scene: str, f_max: float) -> list[dict]:
    """mbcontrol's rows: electrical_bound of the scene at each r2 (BEM included when not cached),
    the force on every multiple of the wave frequency up to f_max (Hz) or the hydro grid's top."""
    from mbcontrol import build_plant, load_scene, waves
    from mbcontrol.analysis.electrical import electrical_bound
    wave = waves.regular(2 * AMPLITUDE, 1 / FREQUENCY)      # WecOptTool's amplitude is ours/2
    rows = []
    for r2 in r2s:
        start = time.perf_counter()
        plant = build_plant(load_scene(scene, {"r2": r2}))
        pto = plant.scene.ptos[0]
        bound = electrical_bound(plant, wave, force_max=pto.force_max, stroke_max=pto.stroke_max,
                                 omega_max=min(float(plant.hydro.omega[-1]), 2 * math.pi * f_max))
        data = plant.hydro.data.isel(omega=int(abs(plant.hydro.data.omega - 2 * math.pi * FREQUENCY).argmin()))
        rows.append({"r2": r2, "power_W": bound.electrical_W, "mechanical_W": bound.mechanical_W,
                     "max_force_N": float(bound.mechanical.max_force),
                     "mass_kg": float(plant.scene.bodies[0].mass),
                     "stiffness_N_per_m": float(plant.hydro.data.hydrostatic_stiffness.values.ravel()[0]),
                     "added_mass_kg": float(data.added_mass.values.ravel()[0]),
                     "damping_N_s_per_m": float(data.radiation_damping.values.ravel()[0]),
                     "wall_s": time.perf_counter() - start})
    return rows


def figure(path: Path, peer, ours) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for rows, label, style in ((peer, "WecOptTool 3.3", "o-"), (ours, "mbcontrol", "s--")):
        r2, p = [r["r2"] for r in rows], [r["power_W"] for r in rows]
        line, = ax.plot(r2, p, style, label=label, mfc="none")
        best = max(range(len(p)), key=p.__getitem__)
        ax.plot(r2[best], p[best], "*", ms=14, color=line.get_color(), label=f"{label} optimum r2 = {r2[best]:.3f} m")
    ax.set_xlabel("keel radius r2 (m), constant displaced volume")
    ax.set_ylabel("optimal mean electrical power (W)")
    ax.set_title("WaveBot r2 study, |F on hull| <= 750 N, a = 0.0625 m at 0.3 Hz", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(ROOT / "out" / "bench" / "wecopttool_codesign"))
    parser.add_argument("--scene", default="wavebot", help="catalogue name or scene path")
    parser.add_argument("--peer-grid", nargs=2, type=float, default=(FREQUENCY, 10),
                        metavar=("F1_HZ", "NFREQ"), help="WecOptTool's f1 and nfreq (default: "
                        "what part 3 runs, 0.3 Hz x 10)")
    args = parser.parse_args(argv)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    peer = run_peer(R2, args.peer_grid[0], int(args.peer_grid[1]))
    peer_s = time.perf_counter() - start
    start = time.perf_counter()
    ours = run_ours(R2, args.scene, args.peer_grid[0] * args.peer_grid[1])
    ours_s = time.perf_counter() - start

    best = {k: max(rows, key=lambda r: r["power_W"])["r2"] for k, rows in (("wecopttool", peer), ("mbcontrol", ours))}
    rows = []
    print(f"WaveBot r2 study (WecOptTool tutorial 1 part 3): |F on hull| <= {FORCE_MAX:.0f} N, "
          f"a = {AMPLITUDE} m at {FREQUENCY} Hz; mean electrical power, BEM included in the times")
    print(f"{'r2 m':>8} {'h2 m':>7} {'WecOptTool':>11} {'mbcontrol':>11} {'difference':>10} "
          f"{'mass kg':>15} {'A(0.3 Hz) kg':>15} {'s/r2':>11}")
    for p, o in zip(peer, ours):
        diff = 100 * (o["power_W"] / p["power_W"] - 1)
        rows.append({"r2_m": p["r2"], "h2_m": p["h2"], "wecopttool_W": p["power_W"],
                     "mbcontrol_W": o["power_W"], "difference_pct": diff,
                     "wecopttool_success": p["success"], "wecopttool_s": p["wall_s"],
                     "mbcontrol_s": o["wall_s"]})
        print(f"{p['r2']:>8.4f} {p['h2']:>7.4f} {p['power_W']:>9.3f} W {o['power_W']:>9.3f} W "
              f"{diff:>+9.3f} % {p['mass_kg']:>7.1f} {o['mass_kg']:>7.1f} "
              f"{p['added_mass_kg']:>7.1f} {o['added_mass_kg']:>7.1f} {p['wall_s']:>5.1f} {o['wall_s']:>5.1f}")
    print(f"optimum r2: WecOptTool {best['wecopttool']:.4f} m, mbcontrol {best['mbcontrol']:.4f} m")
    print(f"wall time, the whole study: WecOptTool {peer_s:.1f} s (its interpreter start and imports "
          f"included), mbcontrol {ours_s:.1f} s")
    figure(out / "wecopttool_codesign.png", peer, ours)
    (out / "wecopttool_codesign.json").write_text(json.dumps(
        {"rows": rows, "optimum_r2_m": best, "peer_grid": {"f1_Hz": args.peer_grid[0],
                                                           "nfreq": int(args.peer_grid[1])},
         "peer": peer, "mbcontrol": ours, "wall_s": {"wecopttool": peer_s, "mbcontrol": ours_s}},
        indent=2))
    print(f"wrote {out / 'wecopttool_codesign.json'} and {out / 'wecopttool_codesign.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
