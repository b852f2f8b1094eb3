"""The main job (`make demo`): the seed's hinged barge from scene to closed-loop simulation.

scene file -> BEM data in body frames -> radiation state-space fit -> process plant ->
linearised control plant (Bode) -> checks against the BEM-direct frequency-domain solution ->
passive PTO damping designed for a sea state -> closed-loop simulation of the nonlinear plant.
Writes figures and summary.json / summary.md into --out.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from . import plotting, waves
from .analysis import (frequency_domain_response, linearize, regular_wave_amplitudes,
                       statespace_response, summary)
from .plant import build_plant
from .sim import simulate
from .textsafe import md_text

MODEL = "hinged_barge"
NO_COULOMB = {"hinge_friction__coulomb": 0.0}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m mbcontrol.demo", description=__doc__,
                                     formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--out", default="out/demo", help="output folder (default out/demo)")
    parser.add_argument("--duration", type=float, default=300.0,
                        help="closed-loop simulation length, s (default 300)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report: dict = {"model": MODEL}
    plant = _hydrodynamics(report)
    sys = _linear(plant, report, out)
    step("3/6 nonlinear time domain vs BEM-direct frequency domain (regular waves, H = 1 cm)")
    report["validation"] = validate(plant, sys, out)
    sea, laws = _design(plant, report, args.duration)
    report["closed_loop"] = _closed_loop(plant, sea, laws, report, out, args.duration)

    step("6/6 summary")
    (out / "summary.json").write_text(json.dumps(report, indent=2, default=float))
    (out / "summary.md").write_text(markdown(report))
    print(f"  wrote {out}/summary.json, summary.md, bode.png, td_vs_fd.png, closed_loop.png")
    return 0


def _hydrodynamics(report: dict):
    """Stage 1: the plant from its scene, hydrodynamics and radiation fit included."""
    step("1/6 scene and hydrodynamics")
    start = time.perf_counter()
    plant = build_plant(MODEL)
    rad = plant.hydro.radiation
    report["plant"] = {"states": len(plant.states), "coordinates": plant.topology.tree
                       .coordinate_names, "hydro_dofs": list(plant.hydro.dofs),
                       "radiation_states": int(rad.order), "radiation_fit_error": rad.fit_error,
                       "build_s": time.perf_counter() - start}
    print(f"  {len(plant.hydro.dofs)} hydro DOFs, radiation model {rad.order} states "
          f"(fit error {rad.fit_error:.2%}), plant built in {report['plant']['build_s']:.2f} s")
    return plant


def _linear(plant, report: dict, out: Path):
    """Stage 2: the linearised plant (no Coulomb friction), its poles and Bode plot."""
    step("2/6 linearised control plant and Bode plot")
    sys = linearize(plant, params=NO_COULOMB)
    poles = np.linalg.eigvals(np.asarray(sys.A))
    omega = np.geomspace(1.0, 30.0, 300)
    pairs = [("u__hinge_pto", "hinge_pto__velocity"), ("w__barge2__Heave", "hinge")]
    plotting.bode(sys, pairs, omega, title="hinged barge, linearised at rest (no Coulomb "
                  "friction)", units={name: plant.units(name) for pair in pairs for name in pair},
                  path=out / "bode.png")
    report["linear"] = {"n_states": int(sys.nstates), "stable": bool(np.all(poles.real < 0)),
                        "slowest_pole_real": float(poles.real.max())}
    print(f"  {sys.nstates} states, stable: {report['linear']['stable']}; bode.png")
    return sys


def _design(plant, report: dict, duration: float):
    """Stage 4: passive and reactive laws tuned for a JONSWAP sea, MPCs set up for it, and
    the complex-conjugate bound: (the sea, {label: controller or None})."""
    step("4/6 passive and reactive PTO laws designed for a JONSWAP sea (Hs 3 cm, Tp 1.1 s)")
    from mbcontrol.controllers import Passive, optimal_damping
    sea = waves.irregular(0.03, 1.1, gamma=3.3, seed=1, duration=duration)
    damping, p_design = optimal_damping(plant, sea)
    c_scene = float(plant.p0[plant.parameters.index("hinge_pto__damping")])
    report["design"] = {"sea": sea.describe(), "scene_damping": c_scene,
                        "optimal_damping": damping, "predicted_power_W": p_design}
    print(f"  optimal PTO damping {damping:.3g} N m s/rad (scene default {c_scene}); predicted "
          f"{p_design * 1e3:.3g} mW (linear, no Coulomb friction)")

    from mbcontrol.controllers import Mpc
    from mbcontrol.controllers import Reactive, reactive_tuning
    limit = plant.scene.ptos[0].force_max
    c_r, k_r, p_r = reactive_tuning(plant, sea, force_max=limit)
    from mbcontrol.analysis import complex_conjugate_bound
    bound = complex_conjugate_bound(plant, sea).power
    report["design"].update(reactive_damping=c_r, reactive_stiffness=k_r,
                            reactive_predicted_power_W=p_r, torque_limit=limit,
                            complex_conjugate_bound_W=bound)
    print(f"  reactive within the {limit:g} N m torque limit: damping {c_r:.3g}, stiffness "
          f"{k_r:.3g} N m/rad; predicted {p_r * 1e3:.3g} mW; complex-conjugate bound "
          f"{bound * 1e3:.3g} mW")
    # a drive's slew limit: a full torque reversal in a fifth of the peak period at the least
    rate = 5 * 2 * limit / sea.period
    report["design"]["mpc_rate_limit"] = rate
    return sea, {f"scene PTO law ({c_scene:g} N m s/rad)": None,
                 "passive, designed": Passive(damping),
                 "reactive, designed": Reactive(c_r, k_r),
                 f"MPC (AR), {limit:g} N m, {rate:.0f} N m/s":
                     Mpc(horizon_s=1.2, dt_s=0.03, wave=sea, forecast="ar", rate_max=rate),
                 f"MPC (AR), {limit:g} N m, no rate limit":
                     Mpc(horizon_s=1.2, dt_s=0.03, wave=sea, forecast="ar")}


def _closed_loop(plant, sea, laws: dict, report: dict, out: Path, duration: float) -> dict:
    """Stage 5: each law in closed loop on the nonlinear plant, checked and plotted: the runs'
    summaries by label."""
    step(f"5/6 closed loop on the nonlinear plant ({duration:.0f} s)")
    runs, records = {}, {}
    for label, controller in laws.items():
        ds = simulate(plant, sea, duration=duration, dt=0.005, controller=controller)
        runs[label], records[label] = summary(ds, plant), ds
        print(f"  {label:34s} mean power {runs[label]['ptos']['hinge_pto']['mean_power_W'] * 1e3:7.3f}"
              f" mW, max torque {runs[label]['ptos']['hinge_pto']['max_force']:.3f} N m, "
              f"simulated at {duration / runs[label]['wall_time_s']:,.0f}x real time")
    failed = {k: r["invalid_reasons"] for k, r in runs.items() if not r["valid"]}
    print("  every run passed its physics checks (power bound of its wave, energy balance, "
          "linear range)" if not failed else
          "\n".join(f"  INVALID {k}: {'; '.join(v)}" for k, v in failed.items()))
    limited, free = (runs[k]["ptos"]["hinge_pto"]["mean_power_W"] for k in list(runs)[-2:])
    rate = report["design"]["mpc_rate_limit"]
    report["design"]["mpc_power_change_by_rate_limit"] = limited / free - 1
    print(f"  the {rate:.0f} N m/s torque-rate limit changes the MPC's power by "
          f"{100 * (limited / free - 1):+.1f} %")
    mean_mw = {k: f"mean {r['ptos']['hinge_pto']['mean_power_W'] * 1e3:.3g} mW"
               for k, r in runs.items()}
    plotting.compare_runs({k: v.sel(time=slice(20, 40)) for k, v in records.items()},
                          ["hinge", "hinge_pto__force", "hinge_pto__power"],
                          title=f"hinged barge in a JONSWAP sea (Hs 3 cm, Tp 1.1 s): each column "
                                f"one controller; 20-40 s of each {duration:g} s run shown, "
                                f"means over each run after its ramp",
                          units={"hinge": "rad", "hinge_pto__force": "N m",
                                 "hinge_pto__power": "mW"},
                          labels={"hinge": "hinge angle", "hinge_pto__force": "PTO torque",
                                  "hinge_pto__power": "absorbed power"},
                          notes={"hinge_pto__power": mean_mw},
                          own_scale=("hinge_pto__power",), scale={"hinge_pto__power": 1e3},
                          path=out / "closed_loop.png")
    return runs


def validate(plant, sys, out: Path) -> dict:
    """Amplitudes at 8 frequencies: nonlinear simulation, state space, BEM-direct FD."""
    omegas = np.geomspace(3.0, 14.0, 8)
    names = ["hinge", "barge2__Heave"]
    fd = np.abs(frequency_domain_response(plant, omegas, params=NO_COULOMB, outputs=names))
    ss = np.abs(statespace_response(sys, plant, omegas, outputs=names))
    td = regular_wave_amplitudes(plant, sys, omegas, names, height=0.01, params=NO_COULOMB)
    dense = np.geomspace(2.0, 20.0, 200)
    fd_dense = np.abs(frequency_domain_response(plant, dense, params=NO_COULOMB, outputs=names))
    plotting.response_comparison(dense, {
        "hinge, BEM-direct FD": (dense, fd_dense[:, 0], "-"),
        "hinge, state space": (omegas, ss[:, 0], "s"),
        "hinge, nonlinear time domain": (omegas, td[:, 0], "x"),
        "barge-2 heave (m/m), BEM-direct FD": (dense, fd_dense[:, 1], "--"),
        "barge-2 heave, nonlinear time domain": (omegas, td[:, 1], "+")},
        ylabel="amplitude per unit wave amplitude (rad/m, m/m)",
        title="hinged barge: response amplitude operators", path=out / "td_vs_fd.png")
    err_td = np.abs(td / fd - 1).max()
    err_ss = np.abs(ss / fd - 1).max()
    print(f"  max |TD/FD - 1| = {err_td:.2%}, max |SS/FD - 1| = {err_ss:.2%}; td_vs_fd.png")
    return {"omega": omegas.tolist(), "max_rel_error_time_domain": float(err_td),
            "max_rel_error_state_space": float(err_ss)}


def markdown(report: dict) -> str:
    """summary.md: the report's numbers; names and run labels through `md_text` (a '|' or a
    newline in one would add a table column or row)."""
    lines = [f"# {md_text(report['model'])}: demo summary", ""]
    p = report["plant"]
    lines += [f"- plant: {p['states']} states, hydro DOFs {md_text(', '.join(p['hydro_dofs']))}; "
              f"radiation {p['radiation_states']} states, fit error "
              f"{p['radiation_fit_error']:.2%}",
              f"- linear model stable: {report['linear']['stable']}",
              f"- time domain vs BEM-direct FD: max amplitude error "
              f"{report['validation']['max_rel_error_time_domain']:.2%}; state space "
              f"{report['validation']['max_rel_error_state_space']:.2%}",
              f"- passive design: damping {report['design']['optimal_damping']:.3g} N m s/rad, "
              f"predicted {report['design']['predicted_power_W'] * 1e3:.3g} mW", "",
              "| run | mean power (mW) | % of complex-conjugate bound | max torque (N m) | "
              "max hinge angle (rad) |", "|---|---|---|---|---|"]
    bound = report["design"]["complex_conjugate_bound_W"]
    for label, r in report["closed_loop"].items():
        pto = r["ptos"]["hinge_pto"]
        lines.append(f"| {md_text(label)} | {pto['mean_power_W'] * 1e3:.3f} | "
                     f"{100 * pto['mean_power_W'] / bound:.1f} | {pto['max_force']:.3f} | "
                     f"{pto['max_stroke']:.4f} |")
    return "\n".join(lines) + "\n"


def step(text: str) -> None:
    print(f"[demo] {text}", flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
