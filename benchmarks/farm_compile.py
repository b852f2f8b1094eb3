"""How a farm's build and compile grow with its size, without the BEM (`make bench`).

array_grid with n x n floats on a *synthetic* hydro model of the real one's sizes (no BEM, no
fit: a 49-float BEM and fit would take most of an hour here): per float, one heave DOF with
A(inf) 14.7 kg, heave stiffness rho g A_wp, a radiation column of `--states` states (2x2 real
modal blocks, poles 0.8-16 rad/s at 30 % damping, the real fit's shape: the 25-float fit has
62 per column) driven by that float's velocity and felt by every float (a dense N x N coupling
decaying with distance, positive semi-definite, so the kernel is passive), excitation of a
heaving cylinder with the incident wave's phase at each float. Same shapes, sparsity and
distinct-number structure (symmetry classes of the grid) as a column fit.

Per grid: build (symbolic plant, s), the RK4 step's C (bytes: deterministic; "data" the constant
arrays of numbers, e.g. a farm's C_r; "code" the rest less comments),
compile (code generation + gcc of the chunk of RK4 steps, s), the output map's compile (s), with
--simulate a JONSWAP run's real-time factor (stepping, outputs excluded); then the growth
exponent of each (slope of log cost against log floats) and the ratio of the two largest grids
(49 / 25 floats: 1.96 if cost is proportional to N).

    python benchmarks/farm_compile.py --n 3 4 5 7 --simulate 60
"""
from __future__ import annotations

import argparse
import json
import os
import re
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np
import xarray as xr

from mbcontrol import waves
from mbcontrol.hydro import HydroModel, RadiationModel
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.sim import simulate
from mbcontrol.sim.integrators import chunk_length, chunk_symbolic, output_function, prepare

RHO, G = 1000.0, 9.81
RADIUS, DRAFT, MASS = 0.2, 0.2, 24.9715612
DURATION, DT = 60.0, 0.01


def grid_positions(n: int) -> np.ndarray:
    """(n^2, 2) float centres (m) of array_grid's n x n grid, 1 m apart, centred."""
    i = np.arange(n * n)
    return np.stack([i % n - (n - 1) / 2, i // n - (n - 1) / 2], axis=1).astype(float)


def _column_block(poles: np.ndarray):
    """A (2m x 2m) real modal blocks [[-s, w], [-w, -s]] at 30 % damping and b = [2, 0] per
    pair (the column fit's form), for pole frequencies `poles` (rad/s)."""
    m = poles.size
    A, b = np.zeros((2 * m, 2 * m)), np.zeros(2 * m)
    for k, w in enumerate(poles):
        s = 0.3 * w
        A[2 * k:2 * k + 2, 2 * k:2 * k + 2] = [[-s, w], [-w, -s]]
        b[2 * k] = 2.0
    return A, b


def synthetic_radiation(n: int, per_column: int, dofs) -> RadiationModel:
    """The radiation model (module docstring): column j's states driven by float j, output
    C[i, column j] = E_ij g^T with E = exp(-(d_ij - 1)) / d_ij off the diagonal (scaled to stay
    positive definite) and g >= 0 weights of the modes: K(s) = E (x) h(s) up to the classes'
    0.5 % pole shifts."""
    xy = grid_positions(n)
    N = n * n
    d = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
    E = np.where(d > 0, 0.3 * np.exp(-(np.where(d > 0, d, 1) - 1)) / np.where(d > 0, d, 1), 1.0)
    E /= max(1.0, 1.1 * (np.abs(E).sum(axis=1) - 1).max())      # diagonally dominant: PD
    np.fill_diagonal(E, 1.0)
    classes = np.round(np.sort(np.abs(xy), axis=1), 6)          # the grid's 8-fold symmetry
    _, label = np.unique(classes, axis=0, return_inverse=True)
    m = per_column // 2
    base = np.geomspace(0.8, 16.0, m)
    A = np.zeros((2 * m * N, 2 * m * N))
    B, C = np.zeros((2 * m * N, N)), np.zeros((N, 2 * m * N))
    for j in range(N):
        a, b = _column_block(base * (1 + 0.005 * label.ravel()[j]))
        cols = slice(2 * m * j, 2 * m * (j + 1))
        A[cols, cols], B[cols, j] = a, b
        g = np.zeros(2 * m)
        g[0::2] = 10.0 * base / m / 2.0                          # kernel weight per mode
        C[:, cols] = E[:, j:j + 1] * g[None, :]
    order = A.shape[0]
    return RadiationModel(A=A, B=B, C=C, D=np.zeros((N, N)), dofs=tuple(dofs), order=order,
                          fit_error=0.0, entry_errors=np.zeros((N, N)),
                          report={"method": "synthetic", "n_states": order})


def synthetic_hydro(n: int, per_column: int = 60) -> HydroModel:
    """A HydroModel for array_grid with n x n floats (module docstring), without BEM."""
    N = n * n
    bodies = [f"float{i + 1}" for i in range(N)]
    dofs = [f"{b}__Heave" for b in bodies]
    xy = grid_positions(n)
    omega = np.concatenate([np.geomspace(0.5, 3.0, 8, endpoint=False), np.linspace(3.0, 14.0, 56)])
    rad = synthetic_radiation(n, per_column, dofs)
    d = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
    A_inf = np.where(d > 0, 0.23 * np.exp(-(np.where(d > 0, d, 1) - 1)) / np.where(d > 0, d, 1),
                     14.71)
    area = np.pi * RADIUS ** 2
    K = RHO * G * area * np.eye(N)
    # the kernel's frequency response, for the added mass and damping on omega
    m = per_column                    # column j's states are j*m .. j*m + m - 1
    H = np.zeros((omega.size, N, N), complex)
    for j in range(N):                # the kernel's response column by column (block diagonal A)
        cols = slice(m * j, m * (j + 1))
        a, b = rad.A[cols, cols], rad.B[cols, j]
        x = np.linalg.solve(1j * omega[:, None, None] * np.eye(m) - a, np.broadcast_to(b, (omega.size, m))[..., None])
        H[:, :, j] = (rad.C[:, cols] @ x)[..., 0]
    added = A_inf[None] + (H.imag / omega[:, None, None])
    headings = np.array([0.0, np.pi / 4])
    k = omega ** 2 / G
    phase = np.exp(1j * k[None, :, None] * (np.cos(headings)[:, None, None] * xy[None, None, :, 0]
                                            + np.sin(headings)[:, None, None] * xy[None, None, :, 1]))
    excitation = RHO * G * area * np.exp(-k * DRAFT / 2)[None, :, None] * phase
    cob = np.column_stack([xy, np.full(N, 0.1)])
    cog = np.column_stack([xy, np.full(N, 0.05)])
    dims2 = ("radiating_dof", "influenced_dof")
    data = xr.Dataset(
        {"added_mass": (("omega",) + dims2, added), "radiation_damping": (("omega",) + dims2, H.real),
         "added_mass_inf": (dims2, A_inf), "hydrostatic_stiffness": (dims2, K),
         "excitation_force": (("wave_direction", "omega", "influenced_dof"), excitation),
         "displaced_volume": (("body",), np.full(N, MASS / RHO)),
         "center_of_buoyancy": (("body", "xyz"), cob), "cog": (("body", "xyz"), cog),
         "mass": (("body",), np.full(N, MASS))},
        coords={"omega": omega, "radiating_dof": dofs, "influenced_dof": dofs,
                "wave_direction": headings, "body": bodies, "xyz": ["x", "y", "z"]},
        attrs={"rho": RHO, "g": G, "depth": np.inf, "time_convention": "exp(-i omega t)",
               "frame": "NED body frames at CoG"})
    return HydroModel(tuple(dofs), data, rad, f"synthetic array_grid {n}x{n}",
                      fit_method="columns")


def c_source(fun: ca.Function) -> str:
    """The C that code generation makes of `fun` (what gcc compiles)."""
    gen = ca.CodeGenerator(f"{fun.name()}.c", {"with_header": False})
    gen.add(fun)
    return gen.dump()


def c_bytes(fun: ca.Function) -> int:
    """Bytes of `fun`'s C."""
    return len(c_source(fun))


def data_bytes(source: str) -> tuple[int, int]:
    """Bytes of a C source's constant arrays of reals (numbers held as data, not code) and of
    its comments (CasADi's, which quote short constants)."""
    data = re.findall(r"static const casadi_real casadi_c\d+\[\d+\] = [^;]*;", source)
    return sum(map(len, data)), sum(map(len, re.findall(r"/\*.*?\*/", source, re.S)))


def measure(n: int, per_column: int, simulate_s: float) -> dict:
    """Build, code size, compile and (optionally) run of the n x n grid, in the cache in force."""
    scene = load_scene("array_grid", {"n": n})
    hydro = synthetic_hydro(n, per_column)
    t0 = time.perf_counter()
    plant = build_plant(scene, hydro)
    t_build = time.perf_counter() - t0
    steps = int(round(DURATION / DT))
    t0 = time.perf_counter()
    source = c_source(chunk_symbolic(plant, "rk4", None, chunk_length(steps)))
    (data, comments), size = data_bytes(source), len(source)
    t_codegen = time.perf_counter() - t0
    t0 = time.perf_counter()
    prepare(plant, steps, "rk4")
    t_compile = time.perf_counter() - t0
    t0 = time.perf_counter()
    output_function(plant, True, chunk_length(steps))
    t_outputs = time.perf_counter() - t0
    row = {"floats": n * n, "states": plant.nx, "build_s": t_build, "c_bytes": size,
           "code_bytes": size - data - comments, "data_bytes": data,
           "codegen_s": t_codegen, "compile_s": t_compile, "outputs_s": t_outputs}
    if simulate_s > 0:
        sea = waves.irregular(0.05, 1.1, gamma=3.3, seed=1, duration=simulate_s,
                              data_band=(0.5, 14.0))
        out = simulate(plant, sea, duration=simulate_s, dt=DT, method="rk4")
        row["rtf"] = simulate_s / out.attrs["wall_time_s"]
        row["finite"] = bool(np.all(np.isfinite(out["state"].values)))
    return row


def growth(rows, key) -> float:
    """Slope of log(cost) against log(floats), over the grids where the cost is not 0."""
    rows = [r for r in rows if r[key] > 0]
    n = np.array([r["floats"] for r in rows], float)
    y = np.array([r[key] for r in rows], float)
    return float(np.polyfit(np.log(n), np.log(y), 1)[0])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[3, 4, 5, 7],
                    help="floats per side (3 4 5 7: 9, 16, 25, 49 floats)")
    ap.add_argument("--states", type=int, default=60, help="radiation states per column (even)")
    ap.add_argument("--simulate", type=float, default=0.0,
                    help="seconds of JONSWAP to run per grid for the real-time factor (0: none)")
    ap.add_argument("--cache", default=None, help="cache folder (default: a fresh one per grid)")
    ap.add_argument("--out", type=Path, default=Path("out/bench/farm_compile"), help="output folder")
    args = ap.parse_args(argv)
    print(f"array_grid, synthetic hydro ({args.states} radiation states per float), RK4 step")
    print(f"{'floats':>6} {'states':>6} {'build (s)':>9} {'C (kB)':>8} {'code':>6} {'data':>6} {'codegen (s)':>11} "
          f"{'compile (s)':>11} {'outputs (s)':>11} {'RTF':>7}")
    rows, previous = [], os.environ.get("MBCONTROL_CACHE")
    for n in args.n:
        with tempfile.TemporaryDirectory() as fresh:
            os.environ["MBCONTROL_CACHE"] = args.cache or fresh
            try:
                r = measure(n, args.states, args.simulate)
            finally:
                if previous is None:
                    os.environ.pop("MBCONTROL_CACHE")
                else:
                    os.environ["MBCONTROL_CACHE"] = previous
        rows.append(r)
        print(f"{r['floats']:6d} {r['states']:6d} {r['build_s']:9.2f} {r['c_bytes'] / 1e3:8.0f} "
              f"{r['code_bytes'] / 1e3:6.0f} {r['data_bytes'] / 1e3:6.0f} "
              f"{r['codegen_s']:11.2f} {r['compile_s']:11.2f} {r['outputs_s']:11.2f} "
              f"{r.get('rtf', float('nan')):7.0f}" + ("" if r.get("finite", True) else " (diverged)"),
              flush=True)
    if len(rows) > 1:
        print("growth exponents (cost ~ floats^k): " + ", ".join(
            f"{k} {growth(rows, k):.2f}" for k in ("build_s", "c_bytes", "code_bytes", "data_bytes",
                                                   "compile_s", "outputs_s")))
        a, b = rows[-2], rows[-1]
        print(f"{b['floats']} over {a['floats']} floats (proportional: {b['floats'] / a['floats']:.2f}x): "
              + ", ".join(f"{k} {b[k] / a[k]:.2f}x" for k in ("build_s", "c_bytes", "code_bytes",
                                                              "compile_s", "outputs_s")))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "farm_compile.json").write_text(json.dumps(rows, indent=2))
    print(f"wrote {args.out / 'farm_compile.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
