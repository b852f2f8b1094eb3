"""`mbcontrol linearize`: the exact linear model about rest, its poles, the PTO laws it
includes (--no-pto-law: none, the open loop a PTO controller faces), and its Bode plot."""
from __future__ import annotations

import json

import numpy as np

from .commands import _key_value, _plant


def add_linearize_flags(p) -> None:
    p.add_argument("--no-pto-law", action="store_true",
                   help="zero every PTO's scene damping and stiffness: the open loop a PTO\n"
                        "controller faces (as design's margins see it); --param still sets them")


def run_linearize(args) -> int:
    from ..analysis import linearize
    plant = _plant(args)
    params = dict(_key_value(s, "--param") for s in args.param)
    if getattr(args, "no_pto_law", False):      # the scene's laws off, --param's kept
        params = {**{f"{p.name}__{k}": 0.0 for p in plant.scene.ptos
                     for k in ("damping", "stiffness")
                     if f"{p.name}__{k}" in plant.parameters}, **params}
    sys_ = linearize(plant, params=params or None)
    poles = np.linalg.eigvals(np.asarray(sys_.A))
    pairs = [tuple(p.split(":", 1)) for p in args.pair] or [
        (f"u__{p.name}", f"{p.name}__velocity") for p in plant.scene.ptos]
    if args.bode:
        from ..plotting import bode
        omega = np.logspace(np.log10(max(plant.hydro.omega[0], 0.05)) if plant.hydro else -1,
                            np.log10(plant.hydro.omega[-1]) if plant.hydro else 2, 400)
        bode(sys_, pairs, omega, path=args.bode)
    info = {"model": plant.name, "n_states": int(sys_.nstates), "states": sys_.state_labels,
            "inputs": sys_.input_labels, "outputs": sys_.output_labels,
            "poles": [[float(p.real), float(p.imag)] for p in poles],
            "stable": bool(np.all(poles.real < 0)), "bode": args.bode,
            "pto_laws": _pto_laws(plant, params),
            "pto_laws_dropped": bool(getattr(args, "no_pto_law", False))}
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        print(f"{plant.name}: {sys_.nstates} states, {sys_.ninputs} inputs, {sys_.noutputs} "
              f"outputs; {'stable' if info['stable'] else 'NOT stable'} (max pole real part "
              f"{poles.real.max():.3g})")
        if info["pto_laws_dropped"]:
            print("  the scene's PTO laws are left out (--no-pto-law)"
                  + ("; --param sets some" if args.param else ""))
        for pto, law in info["pto_laws"].items():
            if any(law.values()):
                print(f"  includes PTO '{pto}' as the scene sets it: " + ", ".join(
                    f"{k} {v:g}" for k, v in law.items()) + " (SI); --no-pto-law leaves the "
                    "scene's laws out")
        if args.bode:
            print(f"Bode plot written to {args.bode}")
    return 0


def _pto_laws(plant, params: dict) -> dict:
    """{pto: {"damping", "stiffness"}}: the PTO laws of the scene (with --param's overrides)
    that the linear model includes (N s/m and N/m, or N m s/rad and N m/rad)."""
    used = plant.params(**params) if params else plant.p0
    return {pto.name: {kind: float(used[plant.parameters.index(f"{pto.name}__{kind}")])
                       for kind in ("damping", "stiffness")
                       if f"{pto.name}__{kind}" in plant.parameters}
            for pto in plant.scene.ptos}
