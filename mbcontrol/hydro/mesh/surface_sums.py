"""Sums over a body's panel points as ONE CasADi call: the mesh path's pressure wrench at scale.

`panels.pressure_wrench` with CasADi inputs writes every point's pressure into one expression
graph. That is right for a few hundred points in calm water, but a wave field's series at each
point (`mbcontrol.waves.LocalField.pressure`, ~250 instructions a point at 8 x 6 terms) makes
megabytes of straight-line C: a 1,563-point mesh did not compile in 9 minutes (gcc killed).

Here the points are cut into blocks of BLOCK; one SX function handles a block; a serial CasADi
map runs it over the blocks (a loop in the generated C) and sums the results; the whole is an
MX Function with ``never_inline`` that an SX graph (the plant's f) keeps as one call node
(CasADi >= 3.7). The generated C grows with the point count only by the points' constant
arrays, and compiles in about a second at any size; derivatives (the plant's Jacobians) come
from CasADi's forward and reverse modes of the same map.

Measured (one core, gcc -O3 -march=native, 200 calls in one compiled map; models/oswec_flap.stl,
1,563 points, field 8 x 6): blocks of 1 point 40 ns a point (the map copies its broadcast
arguments once per block), 8 points 25 ns, 32 points 29 ns; MX elementwise operations over all
points 41 ns. A 1,048-point sphere at 9 x 10: 33 ns a point, of which 11 ns is the floor of
the hydrostatic pressure alone (the transform, the sums and the map's copies). Skipping blocks
above the surface (a short-circuit branch per block) saved nothing measurable: the test of
each block's elevation costs about what the skipped series would. A hand-written C loop over
the points with the series unrolled, vectorised by gcc with the same flags, took 40 ns a point
(1,048 points, 9 x 10): no faster. The last block is padded
with points of zero weight, which add nothing. Benchmarks: benchmarks/nonlinear_fk.py.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .panels import Panels

BLOCK = 8    # points per block: the fastest measured (module docstring)


def _blocks(panels: Panels, block: int):
    """(points, normals, moment arms x n) as 3 x (block * count) arrays, zero-padded."""
    count = math.ceil(panels.n / block)
    out = [np.zeros((3, count * block)) for _ in range(3)]
    out[0][:, :panels.n] = panels.points
    out[1][:, :panels.n] = panels.normals
    out[2][:, :panels.n] = np.cross(panels.points.T, panels.normals.T).T
    return count, out


def _mapped(name: str, extra: list, panels: Panels, block: int, per_block, n_sum: int):
    """MX (extra..., R, r_cog) and the outputs of per_block over all blocks, the first n_sum
    summed, the others (a scalar per block) maxed. per_block(extra SX..., R, X, normals, arms)
    -> SX outputs (body axes; X the block's n-frame points, 3 x block); the points' arrays are
    constants of the function."""
    count, arrays = _blocks(panels, block)
    R, r = ca.SX.sym("R", 3, 3), ca.SX.sym("r_cog", 3)
    points, normals, arms = (ca.SX.sym(s, 3, block) for s in ("points", "normals", "arms"))
    X = ca.repmat(r, 1, block) + ca.mtimes(R, points)
    one = ca.Function(f"{name}_block", [*extra, R, r, points, normals, arms],
                      per_block(*extra, R, X, normals, arms))
    all_blocks = one.map(f"{name}_blocks", "serial", count, list(range(len(extra) + 2)),
                         list(range(n_sum)))
    extra_mx = [ca.MX.sym(f"in{i}", e.sparsity()) for i, e in enumerate(extra)]
    R_mx, r_mx = ca.MX.sym("R", 3, 3), ca.MX.sym("r_cog", 3)
    outs = all_blocks.call([*extra_mx, R_mx, r_mx, *(ca.DM(a) for a in arrays)])   # a list
    return extra_mx, R_mx, r_mx, outs[:n_sum] + [ca.mmax(o) for o in outs[n_sum:]]


def pressure_wrench_function(panels: Panels, pressure_of, n_rows: int, name: str,
                             block: int = BLOCK, largest: bool = False) -> ca.Function:
    """Function (rows (n_rows,), R (3x3), r_cog (3,)) -> (force (3,), moment (3,)): the wrench
    of the pressure p(x, y, z) = pressure_of(rows)(x, y, z) (Pa; CasADi SX 1 x n rows in,
    elementwise, zero where dry) on the posed surface, n-frame axes, moment about the current
    CoG; N and N m. The same numbers as `panels.pressure_wrench`
    (tests/hydro/mesh/test_surface_sums.py), as one never-inlined call.

    largest: pressure_of(rows)(x, y, z) gives (p, v), and a third output is the largest v
    over the points (zero-weight padding included, at the CoG): e.g. how much of its incident
    field's box the surface uses (`LocalField.pressure_and_usage`), from the same pass."""
    rows = ca.SX.sym("rows", n_rows)

    def per_block(rows_, R, X, normals, arms):
        p = pressure_of(rows_)(X[0, :], X[1, :], X[2, :])
        p, extra = (p[0], [ca.mmax(p[1])]) if largest else (p, [])
        return [ca.mtimes(normals, p.T), ca.mtimes(arms, p.T)] + extra

    (rows_mx,), R, r, (force_b, moment_b, *extra) = _mapped(name, [rows], panels, block,
                                                           per_block, 2)
    return ca.Function(name, [rows_mx, R, r], [-ca.mtimes(R, force_b), -ca.mtimes(R, moment_b),
                                               *extra],
                       ["rows", "R", "r_cog"], ["force", "moment"] + ["largest"] * largest,
                       {"never_inline": True})


def calm_water_function(panels: Panels, rho: float, g: float, name: str,
                        block: int = BLOCK) -> ca.Function:
    """Function (R (3x3), r_cog (3,)) -> (force (3,), moment (3,), potential): in calm water,
    the hydrostatic wrench of p = rho g max(z, 0) as `pressure_wrench_function` (N, N m;
    n-frame, about the current CoG), and rho g int_wet z dV (J) by the panel rule
    rho g sum max(z, 0)^2 / 2 n_z (the wet volume closed by the plane z = 0, where the integrand
    vanishes); rho (kg/m^3), g (m/s^2). One never-inlined call."""
    def sums(R, X, normals, arms):
        depth = ca.fmax(X[2, :], 0)
        p = (rho * g) * depth
        return [ca.mtimes(normals, p.T), ca.mtimes(arms, p.T), ca.mtimes(normals, (depth ** 2).T)]

    _, R, r, (force_b, moment_b, second) = _mapped(name, [], panels, block, sums, 3)
    return ca.Function(name, [R, r], [-ca.mtimes(R, force_b), -ca.mtimes(R, moment_b),
                                      0.5 * rho * g * ca.mtimes(R[2, :], second)],
                       ["R", "r_cog"], ["force", "moment", "potential"], {"never_inline": True})
