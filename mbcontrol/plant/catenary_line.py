"""A catenary mooring line of a scene: exact quasi-statics and its CasADi force Function.

The line's geometry is checked by the scene (`mbcontrol.scene.checks.catenary_geometry`), its
statics are `mbcontrol.plant.catenary.solve_catenary`, and the force a plant uses is a table of
exact solutions refined by Newton steps (`CatenaryLine.force_function`).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..scene import Mooring, catenary_geometry
from ..textsafe import c_identifier
from .catenary import SYMBOLIC_OPS, CatenarySolution, shape_terms, solve_catenary


@dataclass(frozen=True)
class ForceTable:
    """A line's CasADi force Function, the table size (points per axis) and Newton steps it
    settled on, and its max force error at 4 points in each cell / rest tension."""
    function: ca.Function
    n_grid: int
    newton_steps: int
    error: float


@dataclass(frozen=True)
class CatenaryLine:
    """One mooring line from a seabed anchor to a fairlead, with a CasADi force Function.

    anchor, fairlead: rest positions, n-frame (z down), m. length: unstretched, m. EA: N.
    weight: submerged, N/m (> 0). excursion: the force table covers fairlead displacements
    from rest up to this, m, horizontally (any direction) and vertically; None: 20 % of the
    rest fairlead height above the anchor. n_grid, newton_steps: the smallest table (points
    per axis) and number of Newton steps `force_table` tries. friction: seabed friction
    coefficient. strain_limit: chord strain beyond which the line is "taut-out".

    Measured with force_table(1e-4); error: max |F - F_exact| / rest tension at 4 points per
    cell, then at 300 random points in the envelope; cost: gcc -O3 C, 2e6 calls, ranges over
    runs on a shared machine; ~45-90 ns for the lookup plus ~40-100 ns per Newton step:
      OC3-Hywind line (L 902.2 m, EA 384 MN, w 698 N/m, XF 848.67 m, ZF 250 m, seabed
        contact), excursion 20 m: 21 x 21, 3 steps, 1.1e-9 / 3.8e-10, 200-350 ns per call.
      WEC chain (L 140 m, EA 500 MN, w 1 kN/m, XF 120 m, ZF 45 m), 10 m, reaching taut:
        41 x 41, 3 steps, 3.7e-6 / 2.7e-9. At XF 90 m, 15 m, crossing the slack boundary:
        21 x 21, 3 steps, 5e-11 / 8e-9.
      Vertical tether snapping between slack and taut (L 44.7 m, ZF 45 m, EA 20 MN), 3 m:
        21 x 21, 8 steps, 4.3e-5 / 1.9e-8, 520-840 ns per call.
    The table alone (no Newton step) errs 2e-2 (21 x 21) and 4e-3 (41 x 41) on OC3; a cubic
    "bspline" interpolant (which also works in SX graphs and codegen; ~380 ns) still errs
    8e-5 at 41 x 41, from the curvature jump at touchdown: hence bilinear + Newton.
    """
    name: str
    anchor: tuple
    fairlead: tuple
    length: float
    EA: float
    weight: float
    excursion: float | None = None
    n_grid: int = 21
    newton_steps: int = 3
    friction: float = 0.0
    strain_limit: float = 0.1

    def __post_init__(self):
        anchor, fairlead, excursion = catenary_geometry(
            f"mooring '{self.name}'", anchor=self.anchor, fairlead=self.fairlead,
            length=self.length, EA=self.EA, weight=self.weight, excursion=self.excursion,
            friction=self.friction, strain_limit=self.strain_limit, n_grid=self.n_grid,
            newton_steps=self.newton_steps)
        object.__setattr__(self, "anchor", anchor)      # frozen: normalise to float tuples
        object.__setattr__(self, "fairlead", fairlead)
        object.__setattr__(self, "excursion", excursion)

    # ------------------------------------------------------------------ exact quasi-statics
    def offsets(self, r) -> tuple[float, float, np.ndarray]:
        """(XF, ZF, d): horizontal distance and height of fairlead position r above the anchor,
        m, and d = (r - anchor) in the horizontal plane (2,)."""
        r = np.asarray(r, dtype=float).reshape(3)
        d = r[:2] - np.asarray(self.anchor[:2])
        return float(np.hypot(*d)), self.anchor[2] - float(r[2]), d

    def solve(self, r=None) -> CatenarySolution:
        """Exact solution with the fairlead at r (n-frame, m; default: at rest)."""
        XF, ZF, _ = self.offsets(self.fairlead if r is None else r)
        return solve_catenary(XF, ZF, self.length, self.EA, self.weight, friction=self.friction,
                              strain_limit=self.strain_limit, name=self.name)

    def force(self, r=None) -> tuple[np.ndarray, float]:
        """Exact force of the line on the fairlead at r (3,), N, n-frame, and tension, N."""
        XF, _, d = self.offsets(self.fairlead if r is None else r)
        sol = self.solve(r)
        e = d / XF if XF > 0.0 else np.zeros(2)
        return np.array([-sol.H * e[0], -sol.H * e[1], sol.V]), sol.tension

    def stiffness(self, r=None) -> np.ndarray:
        """Linearised stiffness K = -dF/dr (3x3, N/m, n-frame) at fairlead position r, by
        implicit differentiation of the exact solution."""
        XF, _, d = self.offsets(self.fairlead if r is None else r)
        sol = self.solve(r)
        (H_X, H_Z), (V_X, V_Z) = sol.stiffness
        vertical = XF <= 1e-9 * self.length
        e = np.array([1.0, 0.0]) if vertical else d / XF
        # sideways the line swings about the anchor: tension H over the lever arm XF (for a
        # vertical line H/XF -> dH/dXF)
        lateral = H_X if vertical else sol.H / XF
        K = np.zeros((3, 3))
        K[:2, :2] = H_X * np.outer(e, e) + lateral * (np.eye(2) - np.outer(e, e))
        K[:2, 2] = -H_Z * e                 # dZF = -dz (z is down)
        K[2, :2] = -V_X * e
        K[2, 2] = V_Z
        return K

    # ------------------------------------------------------------------ CasADi table
    def grid(self, n: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Table nodes (uniform, n per axis, default n_grid) in XF and ZF, m: the rest offsets
        +- excursion, padded by one cell so that the envelope's edge cells have neighbours."""
        XF0, ZF0, _ = self.offsets(self.fairlead)
        n, e = n or self.n_grid, self.excursion
        pad = 2.0 * e / (n - 3)
        xs = np.linspace(max(XF0 - e - pad, 0.0), XF0 + e + pad, n)
        zs = np.linspace(max(ZF0 - e - pad, 1e-3 * ZF0), ZF0 + e + pad, n)
        return xs, zs

    def _table(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Grid (see `grid`) and exact H, V on it, N, shape (2, n, n)."""
        xs, zs = self.grid(n)
        HV = np.empty((2, n, n))
        for i, x in enumerate(xs):
            for j, z in enumerate(zs):
                sol = self.solve(np.array(self.anchor) + (x, 0.0, -z))
                HV[:, i, j] = sol.H, sol.V
        return xs, zs, HV

    def _function(self, table: tuple, steps: int) -> ca.Function:
        """The force Function from a `_table` and `steps` Newton steps (see `force_table`)."""
        L, EA, w, cb, a = self.length, self.EA, self.weight, self.friction, self.anchor
        ident = c_identifier(self.name)   # a valid CasADi name, distinct for distinct names
        xs, zs, HV = table
        # CasADi orders values with the output index fastest, then the first grid axis;
        # "exact" lookup finds the cell of a uniform grid arithmetically, but accepts only
        # grids spaced equally to 1e-14 of their span: offsets from the first node are
        local = [np.linspace(0.0, g[-1] - g[0], g.size) for g in (xs, zs)]
        lookup = ca.interpolant(f"mooring_{ident}_HV", "linear", local, HV.ravel(order="F"),
                                {"lookup_mode": ["exact", "exact"]})
        r = ca.SX.sym("r", 3)
        dx, dy, ZF = r[0] - a[0], r[1] - a[1], a[2] - r[2]
        # smoothed horizontal distance: a finite direction when the line is vertical (XF -> 0),
        # biased by delta^2/(2 XF) elsewhere, i.e. 5e-13 L at XF = L
        delta = 1e-6 * L
        XF = ca.sqrt(dx * dx + dy * dy + delta * delta)
        guess = lookup(ca.vertcat(XF - xs[0], ZF - zs[0]))
        # the shape equations need H > 0: start no lower than a millionth of the line weight
        h, v = ca.fmax(guess[0], 1e-6 * w * L), ca.fmax(guess[1], 1e-6 * w * L)
        for _ in range(steps):
            x, z, XH, XV, ZH, ZV = shape_terms(h, v, L, EA, w, cb, SYMBOLIC_OPS)
            det = XH * ZV - XV * ZH
            dh = -(ZV * (x - XF) - XV * (z - ZF)) / det
            dv = -(XH * (z - ZF) - ZH * (x - XF)) / det
            # keep H and V positive, as the exact solver does (inactive near convergence)
            h, v = ca.fmax(h + dh, 0.1 * h), ca.fmax(v + dv, 0.1 * v)
        hanging = 2.0 * ZF / (1.0 + ca.sqrt(1.0 + 2.0 * w * ZF / EA))
        slack = XF <= L - hanging
        h, v = ca.if_else(slack, 0.0, h), ca.if_else(slack, w * hanging, v)
        F = ca.vertcat(-h * dx / XF, -h * dy / XF, v)
        return ca.Function(f"mooring_{ident}", [r], [F, ca.sqrt(h * h + v * v)], ["r"],
                           ["F", "T"])

    def force_table(self, tolerance: float = 1e-4, max_grid: int = 41,
                    max_steps: int = 8) -> ForceTable:
        """The force Function with the cheapest table (n_grid, doubled up to max_grid points
        per axis) and Newton steps (newton_steps up to max_steps) whose force error at 4 points
        in every cell is below `tolerance` x the rest tension; if none, warns and returns the
        most accurate.

        The Function maps r (3x1, fairlead position, n-frame, m) to F (3x1, force of the line
        on the fairlead, n-frame, N) and T (1x1, fairlead tension, N). In the slack zone
        (XF <= L - L_h(ZF)) H = 0 and V = w L_h exactly; elsewhere a bilinear table of the
        exact H, V starts Newton steps on the exact shape equations, which remove the table's
        error and give the derivative of the exact solution (up to the residual). It takes SX
        or MX (the table is a call node in SX graphs) and generates C with CodeGenerator.
        Outside the envelope the table extrapolates and Newton may not converge.
        """
        sizes = [self.n_grid]
        while sizes[-1] < max_grid:
            sizes.append(min(2 * sizes[-1] - 1, max_grid))
        tables, checks, best = {}, {}, None
        # runtime cost grows with the steps, not the grid: try every grid before a new step
        for steps in range(self.newton_steps, max(max_steps, self.newton_steps) + 1):
            for n in sizes:
                if n not in tables:
                    tables[n] = self._table(n)
                    # interpolation errs most inside cells: check 4 points in every cell
                    xs, zs, _ = tables[n]
                    X, Z = np.meshgrid(*[np.r_[0.75 * g[:-1] + 0.25 * g[1:],
                                                 0.25 * g[:-1] + 0.75 * g[1:]] for g in (xs, zs)])
                    points = np.array(self.anchor) + np.c_[X.ravel(), 0 * X.ravel(), -Z.ravel()]
                    checks[n] = points, np.array([self.force(p)[0] for p in points])
                fun = self._function(tables[n], steps)
                error = self._error(fun, *checks[n])
                if best is None or error < best.error:
                    best = ForceTable(fun, n, steps, error)
                if error <= tolerance:
                    return best
        warnings.warn(f"mooring '{self.name}': force table error {best.error:.2g} of the rest "
                      f"tension ({best.n_grid} x {best.n_grid} grid, {best.newton_steps} Newton "
                      f"steps) exceeds {tolerance:g}; reduce the excursion, or raise max_grid "
                      f"or max_steps", RuntimeWarning, stacklevel=2)
        return best

    def force_function(self, tolerance: float = 1e-4) -> ca.Function:
        """`force_table(tolerance).function`: r (3x1, m) -> (F (3x1, N), T (1x1, N))."""
        return self.force_table(tolerance).function

    def table_error(self, fun: ca.Function, n: int = 300, seed: int = 0) -> float:
        """Max |F_fun - F_exact| over n random fairlead positions in the envelope (a cylinder:
        up to `excursion` horizontally and vertically), relative to the rest tension."""
        rng = np.random.default_rng(seed)
        angle = rng.uniform(0.0, 2.0 * np.pi, n)
        radius = self.excursion * np.sqrt(rng.uniform(size=n))
        points = np.array(self.fairlead) + np.c_[radius * np.cos(angle), radius * np.sin(angle),
                                                 rng.uniform(-1.0, 1.0, n) * self.excursion]
        return self._error(fun, points, np.array([self.force(p)[0] for p in points]))

    def _error(self, fun: ca.Function, points: np.ndarray, exact: np.ndarray) -> float:
        """Max |F_fun - exact| at fairlead positions `points` (m, (k, 3)) / rest tension."""
        table = np.array(fun.map(len(points))(points.T)[0]).T
        return float(np.max(np.abs(table - exact))) / self.solve().tension


def catenary_line(m: Mooring) -> CatenaryLine:
    """The CatenaryLine of a scene's catenary mooring."""
    return CatenaryLine(name=m.name, anchor=m.anchor, fairlead=m.point, length=m.length, EA=m.EA,
                        weight=m.weight, excursion=m.excursion)
