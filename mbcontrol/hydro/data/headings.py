"""Excitation at any wave direction from data at a few headings, and the headings a spread
sea needs from a BEM.

Between the data's headings the per-unit-amplitude excitation (already interpolated to the
wanted frequency) is interpolated in heading as complex values by a cubic spline (periodic
where the headings cover the whole circle: the gap across +-pi no wider than the widest gap
between them; straight lines with fewer than four headings). Complex, not magnitude and
unwrapped phase: DOFs antisymmetric about the mean direction (sway, roll, yaw in head seas)
pass through zero as the heading crosses it, where the phase jumps by pi and a magnitude/phase
interpolation would invent a force; complex values are smooth there. A spline, not straight
lines: a chord cuts inside the curve F(b) traces, so |F|^2 and the power dip between headings;
on the OSWEC (15 deg headings, cos-2s sigma 30 deg) straight lines put the expected power 1.2 %
below the periodic trapezoid over the data's headings, the spline within 0.1 %. Error grows
with the plane wave's own phase k (x cos b + y sin b) over a step: the catalogue bodies sit
near the n-frame origin; a body far from it needs k r db small. A direction outside the data's
headings is refused, naming the source, its headings and what gives data there
(`headings_remedy`: the `[hydro] headings` line where Capytaine computes the data, another BEM
run where a file supplies them, `[hydro] axisymmetric` where one heading can serve all)."""
from __future__ import annotations

import math

import numpy as np

from ...errors import HydroError

TOL = 1e-6                  # rad: a direction this close to a heading is that heading
SECTOR_SIGMAS = 3.0         # a spread sea's directions are kept within mean +- 3 sigma
STEP = math.radians(15.0)   # rad: the largest heading step `headings_for_spread` gives


def headings_for_spread(mean: float, spread: float, step: float = STEP,
                        sigmas: float = SECTOR_SIGMAS) -> np.ndarray:
    """The BEM headings (rad, NED) a sea spread by sigma = `spread` (rad) about `mean` (rad)
    needs: mean +- sigmas sigma on a uniform step no larger than `step` (rad), or the whole
    circle [-pi, pi) on such a step when that sector reaches +-pi."""
    if not (step > 0 and spread > 0 and math.isfinite(mean)):
        raise HydroError(f"headings_for_spread: expected spread > 0 and step > 0 (rad), got "
                         f"{spread!r}, {step!r}")
    half = sigmas * spread
    if half >= math.pi - 1e-9:
        n = math.ceil(2 * math.pi / step)
        return -math.pi + 2 * math.pi * np.arange(n) / n
    n = math.ceil(2 * half / step)
    return mean + np.linspace(-half, half, n + 1)


def axisymmetric_headings(data, source: str, step: float = STEP):
    """`data` with its one heading's excitation given at every `step` (rad) round the circle:
    for bodies of revolution about the n-frame z axis moving in heave only, the heave
    excitation does not depend on the direction the waves travel (a rotation about z maps
    the bodies and the heave force onto themselves). HydroError naming `source` when a DOF is
    not heave or a body's CoG or centre of buoyancy lies off the z axis (1 mm); data with
    several headings are returned as they are."""
    if data.sizes.get("wave_direction", 1) > 1:
        return data
    dofs = [str(d) for d in data["influenced_dof"].values]
    other = [d for d in dofs if not d.endswith("__Heave")]
    if other:
        raise HydroError(f"{source}: axisymmetric data serve every direction in heave only; "
                         f"the data also hold {other}")
    for name in ("cog", "center_of_buoyancy"):
        if name in data:
            xy = np.asarray(data[name].transpose("body", "xyz").values, float)[:, :2]
            if np.any(np.abs(xy) > 1e-3):
                raise HydroError(f"{source}: axisymmetric data need every body on the z axis; "
                                 f"{name} (x, y) = {np.round(xy, 4).tolist()} m")
    n = math.ceil(2 * math.pi / step)
    headings = -math.pi + 2 * math.pi * np.arange(n) / n
    out = data.reindex(wave_direction=headings, method="nearest", tolerance=2 * math.pi)
    out["wave_direction"].attrs = dict(data["wave_direction"].attrs)
    out.attrs["axisymmetric"] = (f"heading {float(data['wave_direction'].values[0]):.4g} rad "
                                 f"given every {math.degrees(step):.4g} deg (bodies of "
                                 f"revolution in heave)")
    return out


def covers_circle(headings) -> bool:
    """True when headings (rad) cover the whole circle: three or more, and the gap across
    the wrap no wider than the widest gap between neighbours (interpolation wraps there)."""
    return _layout(headings)[3]


def headings_line(headings) -> str:
    """The scene's `[hydro] headings = [...]` line for `headings` (rad), in degrees."""
    return "headings = [" + ", ".join(f'"{math.degrees(float(h)):.4g} deg"'
                                      for h in headings) + "]"


def headings_remedy(source: str, have, wanted) -> str:
    """What gives excitation data at the headings `wanted` (rad) when the data from `source`
    hold only `have` (rad). `[hydro] headings` is read only when Capytaine computes the data
    from the scene's geometry (module model: its source then starts "BEM"); a supplied file
    (WAMIT, BEMIO, Capytaine, or the catalogue's converted .nc) holds the headings its own run
    solved, so the remedy there is another run. With one heading, `[hydro] axisymmetric = true`
    (axisymmetric_headings) serves every direction where the bodies allow it."""
    line = headings_line(wanted)
    if str(source).startswith(("BEM ", "BEM,")):
        text = f"compute them: in the scene's [hydro] table, {line}"
    else:
        text = (f"the file holds the headings its BEM run solved, so these need another run: "
                f"yours at these headings, given as [hydro] source (a WAMIT .out, BEMIO .h5 or "
                f"Capytaine .nc file), or Capytaine's from the bodies' geometry ([hydro] omega "
                f"and {line}, without [hydro] file and source)")
    if np.size(have) == 1:
        text = ("if every body is a body of revolution about the n-frame z axis moving in heave "
                "only, its one heading serves every direction: [hydro] axisymmetric = true; "
                "otherwise " + text)
    return text + "; mbcontrol.hydro.headings_for_spread gives the headings a spread sea needs"


def _layout(headings):
    """(h0, r, periodic): the first heading, the others' offsets from it in [0, 2 pi), sorted,
    and whether the data cover the circle (the gap across the wrap no wider than the widest
    gap between neighbouring headings)."""
    h = np.asarray(headings, float)
    h0 = float(h.min())
    r = (h - h0) % (2 * math.pi)
    order = np.argsort(r)
    r = r[order]
    if r.size < 3:
        return h0, r, order, False
    wrap_gap = 2 * math.pi - r[-1]
    return h0, r, order, bool(wrap_gap <= np.max(np.diff(r)) * (1 + 1e-6))


def covering_headings(direction, step: float = STEP) -> np.ndarray:
    """Headings (rad) on a uniform step <= `step` spanning all of `direction` (rad) about
    their circular mean (the whole circle when they reach +-pi from it)."""
    d = np.atleast_1d(np.asarray(direction, float))
    mean = float(np.angle(np.mean(np.exp(1j * d))))
    half = float(np.max(np.abs((d - mean + math.pi) % (2 * math.pi) - math.pi)))
    if half >= math.pi - step:
        return headings_for_spread(mean, math.pi, step, sigmas=1.0)
    n = max(1, math.ceil(2 * half / step))
    return mean + np.linspace(-half, half, n + 1) if half > TOL else np.array([mean])


def heading_matrix(headings, direction, source: str) -> np.ndarray:
    """(n_directions, n_headings): the weights that give the excitation at each direction (rad)
    from the data's at each heading (F(theta) = sum_j M_j(theta) F_j): a cubic spline's
    cardinal functions (periodic where the headings cover the circle, not-a-knot otherwise)
    with four headings or more, straight lines between two or three, the heading itself with
    one. HydroError naming `source` and the data's headings when a direction lies outside
    them (or the data repeat a heading)."""
    d = np.atleast_1d(np.asarray(direction, float))
    h0, r, order, periodic = _layout(headings)
    if np.any(np.diff(r) < TOL):
        raise HydroError(f"{source}: the excitation data repeat a heading "
                         f"({np.round(np.degrees(np.asarray(headings, float)), 3).tolist()} deg)")
    phi = (d - h0) % (2 * math.pi)
    phi = np.where(phi > 2 * math.pi - TOL, 0.0, phi)        # just below the first heading
    ext, idx = (np.append(r, 2 * math.pi), np.append(order, order[0])) if periodic else (r, order)
    bad = np.abs(phi - ext[0]) > TOL if ext.size == 1 else phi > ext[-1] + TOL
    if np.any(bad):
        shown = np.degrees(np.asarray(headings, float))
        worst = np.degrees(d[bad])
        raise HydroError(
            f"{source}: wave directions {worst.min():.4g}..{worst.max():.4g} deg "
            f"({int(bad.sum())} of {d.size} components) lie outside the excitation data's "
            f"headings {np.round(shown, 2).tolist()} deg and cannot be interpolated; "
            f"{headings_remedy(source, headings, covering_headings(d))}")
    n = len(headings)
    basis = np.zeros((ext.size, n))
    basis[np.arange(ext.size), idx] = 1.0
    phi = np.clip(phi, ext[0], ext[-1])
    if ext.size >= 4 + periodic:
        from scipy.interpolate import CubicSpline    # here: one heading's data need no spline
        spline = CubicSpline(ext, basis, bc_type="periodic" if periodic else "not-a-knot")
        return spline(phi)
    if ext.size == 1:
        return np.repeat(basis, d.size, axis=0)
    return np.stack([np.interp(phi, ext, basis[:, j]) for j in range(n)], axis=1)


def excitation_over_headings(per_heading, weights) -> np.ndarray:
    """Per-component coefficients (n, n_dof) from per_heading (n_headings, n, n_dof) (the
    data at each heading, already at the components' frequencies) and `heading_matrix`."""
    return np.einsum("ih,hid->id", weights, per_heading)
