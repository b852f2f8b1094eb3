"""Closed panel surfaces of bodies and the pressure wrench over them: the mesh path of nonlinear
hydrostatics and Froude-Krylov forces.

Frames and units: n-frame NED (x forward, y starboard, z down, origin on the undisturbed free
surface, water at z > 0); body axes coincide with the n-frame axes at rest. SI units. A body is
a set of quadrature points on its CLOSED surface (above and below the waterline), each with an
area-weighted outward normal; a pressure p gives the force -sum p_i n_i and its moment.
:func:`pressure_wrench` takes numpy or CasADi inputs; with CasADi it is a pure expression (1 x N
rows, no loops over points, no branching on values) for a compiled plant. Every rule is exact
for the force of a pressure linear in position over the whole surface (Archimedes; sum of
normals 0, sum of points . normals / 3 the exact volume, to round-off), and for its moment but
on sloping stretches of a revolution profile (~1e-5 m of lever): box faces cut into rectangles
(:func:`_box`); cylinders (axis x, y, z) and revolutions on their exact surface of revolution,
closed by disks where r > 0 at the ends (:func:`_revolved`); the sphere in rings of exact area
(:func:`_sphere`); a mesh file's flat triangles (a quad split on a diagonal keeps its vector
area), points at the edge midpoints of s^2 sub-triangles (:func:`_triangle_points`, 1.5 points
per triangle at s = 1). Points of neighbouring cells of the primitives are staggered a quarter
cell so that a waterline along the rows meets two depths per row.

``subdivide`` s puts s x s sub-cells in each panel: on the exact-geometry primitives that is the
rule of ``panel_size / s``; on a mesh file it resolves the waterline better at the same facets.
Default ``panel_size``: sqrt(surface area / 500), 580-750 points for compact primitives (sphere
584, boxes 640, cylinders 690-750); a mesh file's default is its own faces. A revolution profile
of many short segments gets at least one ring per segment.

Accuracy and cost (measured; tests/hydro/mesh/test_panels.py checks the default)
--------------------------------------------------------------------------
The only error on a primitive is the kink of max(z, 0) in the cells the waterline cuts: second
order in the cell size, irregular in the draft. Worst relative force error, sphere R = 5 m,
centre depth -0.6, -0.3, 0, 0.3, 0.6 R x heel 0, 10, 30, 60 deg about an oblique axis, against
the exact cap (exact geometry) or the exactly clipped polyhedron (UV-sphere mesh file of
inscribed quads, whose own geometry error, 3-13 % of the cap, is not counted):

==============================  ======  ======  ======  ======  ======  ======
exact geometry, points             208     376     696    1368    2624    5104
force error                     7.5e-3  5.9e-3  1.6e-3  1.4e-3  3.1e-4  3.3e-4
mesh file, faces (points, s=1)   s = 1   s = 2   s = 3  (points x 4 and x 9)
128 quads (336)                 5.8e-3  1.8e-3  4.4e-4
288 quads (792)                 1.4e-2  5.0e-4  1.1e-3
512 quads (1440)                2.0e-3  9.4e-4  3.1e-4
==============================  ======  ======  ======  ======  ======  ======

Default: sphere (584 points) 2.3e-3; boxes 2 x 1 x 1 and 4 x 2 x 0.5 (640 points; exact clipped
polyhedron, heel 0-30 deg, 15-85 % wet) 2.0e-3, moments 1e-3 of force x length; cylinders
(against large_angle, n = 64; heel 0-30 deg, 25-75 % wet) 9e-4 vertical, 5.3e-3 horizontal (its
waterline runs along the rings), moments 4e-4 and 7e-4 of force x length. Upright boxes and
vertical cylinders are exact (only their flat bottoms carry vertical force).

Compiled (CasADi SX Function (R, r_cog) -> (force, moment), :func:`hydrostatic_pressure`,
``mbcontrol.sim.compiled.compile_function``, gcc -O3 -march=native, one core, 10^4 poses in one
mapped call): 5-6 ns per point; 584 points 3.4 us per evaluation (1.4 s to compile 284 kB of C),
1563 (models/oswec_flap.stl) 7.2 us (4 s), 2624 points 14 us (18 s, 1.4 MB). MX inputs work too:
~2.3x slower (6.7, 17, 28 us) but 0.2 s to compile at any size. numpy 35 us, SX VM 62 us.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from mbcontrol.errors import HydroError
from mbcontrol.scene import profile_problem

POINTS_TARGET = 500     # default panel_size = sqrt(surface area / POINTS_TARGET)
CLOSED_TOL = 1e-6       # a mesh is closed when sum(n) / area and the second-moment check pass
NED_TO_ZUP = np.diag([1.0, -1.0, -1.0])   # z-up mesh files <-> NED; its own inverse, det +1
_AXES = {"z": np.eye(3),                                       # body of revolution about z ->
         "x": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]),   # e_z to e_x (rotation about y)
         "y": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])}   # e_z to e_y (rotation about x)


@dataclass(frozen=True)
class Panels:
    """Quadrature points of a body's CLOSED surface (whole hull: above and below the waterline).

    Attributes
    ----------
    points : (3, N) m, body axes, relative to the CoG at rest.
    normals : (3, N) m^2, outward unit normal times the point's area weight; for a closed
        surface sum(normals, axis=1) == 0 and sum(points * normals) / 3 == volume.
    """

    points: np.ndarray
    normals: np.ndarray

    @property
    def n(self) -> int:
        """Number of quadrature points."""
        return int(self.points.shape[1])

    @property
    def volume(self) -> float:
        """Enclosed volume, m^3 (divergence theorem: sum of points . normals / 3)."""
        return float(np.sum(self.points * self.normals) / 3.0)


# ----------------------------------------------------------------------------- primitives
def _rings(h: float, r_max: float, count_min: int = 8) -> int:
    """Cells around a ring of radius ``r_max`` for a cell size ``h``: a multiple of 4 (each
    staggered sub-band an even polygon, mirror-symmetric), at least ``count_min``."""
    return max(count_min, 4 * math.ceil(2 * math.pi * r_max / (4 * h) - 1e-9))


def _ring_points(r, z, nr, nz, weight, count: int, parity: int = 0):
    """Points of one ring band split into two sub-bands along the profile: ``count`` cells at
    angles j 2 pi / count, those with j = parity (mod 2) at sub-band 0, the others at 1.

    r, z, nr, nz, weight: pairs (one per sub-band): radius and z of the point (m), unit normal
    (radial, z) and area weight (m^2). The stagger doubles the depths a horizontal waterline
    meets for the same points (the upright sphere's worst force error falls 5x); each sub-band
    is a regular count/2-gon with points on the x = 0 and y = 0 planes: both mirror symmetries
    hold and its sums of cos^2, sin^2 are exact. Returns (points, normals), each (3, count)."""
    half = count // 2
    phi = (2 * np.arange(half)[None, :] + (np.arange(2)[:, None] + parity) % 2) * (2 * math.pi / count)
    c, s = np.cos(phi), np.sin(phi)                        # (2 sub-bands, half)
    r, z, nr, nz, w = (np.asarray(v, dtype=float)[:, None] * np.ones((1, half))
                       for v in (r, z, nr, nz, np.asarray(weight) / half))
    return (np.vstack([(r * c).ravel(), (r * s).ravel(), z.ravel()]),
            np.vstack([(w * nr * c).ravel(), (w * nr * s).ravel(), (w * nz).ravel()]))


def _revolved(profile: np.ndarray, h: float, even: bool = False):
    """Points and normals of the closed surface of revolution about z of ``profile`` (r, z),
    a polyline from the top (z smallest) to the keel with r = 0 at both ends. The stagger
    parity alternates along a segment; with ``even`` (an even number of cells per segment) a
    profile symmetric about z = 0 gives points symmetric about it (a horizontal cylinder at
    rest then feels no surge force or pitch moment)."""
    parts = []
    for (ra, za), (rb, zb) in zip(profile[:-1], profile[1:]):
        dr, dz = rb - ra, zb - za
        length = math.hypot(dr, dz)
        nr, nz = dz / length, -dr / length                 # outward: walking down, water on the left
        k = max(1, math.ceil(length / h - 1e-9))
        k += k % 2 if even else 0
        t1, t2 = np.arange(2 * k) / (2 * k), np.arange(1, 2 * k + 1) / (2 * k)   # half cells
        r_int = ra * (t2 - t1) + dr * (t2**2 - t1**2) / 2             # int r dt
        t_int = ra * (t2**2 - t1**2) / 2 + dr * (t2**3 - t1**3) / 3   # int t r dt
        tc = t_int / r_int                                 # r-weighted centroid of [t1, t2]
        r_out = ra + dr * (t2[1::2] if dr > 0 else t1[::2])  # outer radius of each cell
        for i in range(k):
            band = slice(2 * i, 2 * i + 2)
            parts.append(_ring_points(ra + dr * tc[band], za + dz * tc[band], (nr, nr), (nz, nz),
                                      2 * math.pi * length * r_int[band], _rings(h, r_out[i]), i % 2))
    return tuple(np.hstack(a) for a in zip(*parts))


def _sphere(radius: float, h: float):
    """Points and normals of a sphere about the origin: rings of equal polar-angle width, each
    two sub-bands, points at a sub-band's RMS cos(polar angle) (exact area, volume and second
    moments: Archimedes holds exactly)."""
    n_lat = 2 * max(1, math.ceil(math.pi * radius / (2 * h) - 1e-9))
    u = np.cos(np.linspace(0.0, math.pi, 2 * n_lat + 1))           # sub-band edges, 1 to -1
    u2, u1 = u[:-1], u[1:]
    uc = np.copysign(np.sqrt((u1 * u1 + u1 * u2 + u2 * u2) / 3), u1 + u2)
    sc = np.sqrt(np.maximum(1.0 - uc * uc, 0.0))
    weight = 2 * math.pi * radius**2 * (u2 - u1)
    parts = []
    for i in range(n_lat):
        band = slice(2 * i, 2 * i + 2)
        ring_r = radius * math.sqrt(max(1.0 - min(u[2 * i] ** 2, u[2 * i + 2] ** 2), 0.0))
        parts.append(_ring_points(radius * sc[band], radius * uc[band], sc[band], uc[band],
                                  weight[band], _rings(h, ring_r), i % 2))
    return tuple(np.hstack(a) for a in zip(*parts))


def _box(size, h: float):
    """Points and normals of a box about the origin: each face cut into an even number of cells
    <= h each way, the points a quarter cell off the centres along b (z on the sides, y on top
    and bottom), the sign in a checkerboard. Against the cell centres, for the same points: force
    errors 2-3x smaller, moments no worse; with even counts the offsets are uncorrelated with any
    linear function on the face, so its first moments (hence Archimedes) stay exact."""
    size = np.asarray(size, dtype=float)
    parts = []
    for axis in range(3):
        a, b = (c for c in range(3) if c != axis)
        ka, kb = (2 * max(1, math.ceil(size[c] / (2 * h) - 1e-9)) for c in (a, b))
        i, j = (g.ravel() for g in np.meshgrid(np.arange(ka), np.arange(kb), indexing="ij"))
        p = np.zeros((3, i.size))
        p[a] = ((i + 0.5) / ka - 0.5) * size[a]
        p[b] = ((j + 0.5 + 0.25 * (1 - 2 * ((i + j) % 2))) / kb - 0.5) * size[b]
        n = np.zeros((3, i.size))
        for sign in (1.0, -1.0):
            p[axis], n[axis] = sign * size[axis] / 2, sign * size[a] * size[b] / (ka * kb)
            parts.append((p.copy(), n.copy()))
    return tuple(np.hstack(a) for a in zip(*parts))


def _closed(profile) -> np.ndarray:
    """A revolution profile (r, z) closed to the axis at both ends by flat disks."""
    p = np.asarray(profile, dtype=float).reshape(-1, 2)
    if p[0, 0] > 0:
        p = np.vstack([[0.0, p[0, 1]], p])
    if p[-1, 0] > 0:
        p = np.vstack([p, [0.0, p[-1, 1]]])
    return p


# ----------------------------------------------------------------------------- mesh files
def _mesh_triangles(g: dict) -> np.ndarray:
    """Triangles (F, 3 corners, 3) of a mesh file in the n-frame at rest, m."""
    import capytaine as cpt

    name = g.get("file")
    try:
        mesh = cpt.load_mesh(str(name)).merged()
    except Exception as exc:
        raise HydroError(f"mesh file {name!r} could not be read ({type(exc).__name__}: {exc})") from exc
    v = np.asarray(mesh.vertices, dtype=float)
    v = v if g.get("axes", "z_up") == "ned" else v @ NED_TO_ZUP      # z-up file -> NED
    v = v + np.asarray(g.get("center", (0.0, 0.0, 0.0)), dtype=float).reshape(3)
    f = np.asarray(mesh.faces, dtype=int).reshape(-1, 4)
    quad = (f[:, 3] != f[:, 2]) & (f[:, 3] != f[:, 0])
    # a quad split on its diagonal keeps its vector area (1/2 d1 x d2), so closure is kept
    tri = v[np.vstack([f[:, :3], f[quad][:, [0, 2, 3]]])]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return tri[area > 0]                                   # a repeated corner makes no point


def _triangle_points(tri: np.ndarray, s: int):
    """Edge midpoints (M, 3) and weights (M, 3) of the s^2 congruent sub-triangles of each
    triangle, each a third of its sub-triangle's area vector: exact for quadratics, so for the
    moment of a linear pressure too (centroids err by 4e-3 R F on a submerged faceted sphere)."""
    a, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    cells = [((i, j), (i + 1, j), (i, j + 1)) for i in range(s) for j in range(s - i)]
    cells += [((i + 1, j), (i + 1, j + 1), (i, j + 1)) for i in range(s - 1) for j in range(s - 1 - i)]
    uv = np.array([np.add(t[k], t[k - 1]) / (2 * s) for t in cells for k in range(3)])
    pts = a[None] + uv[:, :1, None] * e1[None] + uv[:, 1:, None] * e2[None]    # (3 s^2, F, 3)
    return pts.reshape(-1, 3), np.broadcast_to(np.cross(e1, e2) / (6 * s * s), pts.shape).reshape(-1, 3)


def _check_closed(name, points: np.ndarray, normals: np.ndarray) -> None:
    """Raise HydroError unless the surface is closed with outward normals: sum n = 0 and
    sum x n^T = V I (then any linear pressure field gives exactly Archimedes' force)."""
    area = float(np.sum(np.linalg.norm(normals, axis=0)))
    second = (points - points.mean(axis=1, keepdims=True)) @ normals.T     # = V I if closed
    vol = np.trace(second) / 3
    size = float(np.max(np.ptp(points, axis=1)))
    gap = max(np.linalg.norm(normals.sum(axis=1)) / area,
              np.abs(second - vol * np.eye(3)).max() / (area * size))
    if not gap <= CLOSED_TOL:
        raise HydroError(
            f"mesh file {name!r} is not a closed surface (sum of normals / area or the second-"
            f"moment check off by {gap:.2g} > {CLOSED_TOL:g}): the nonlinear hydrostatic and "
            "Froude-Krylov forces need the whole hull, above and below the waterline (many BEM "
            "meshes hold only the wetted part); export the closed hull")
    if vol <= 0:
        raise HydroError(f"mesh file {name!r}: its normals point inward (enclosed volume "
                         f"{vol:.4g} m^3); expected outward normals")


# ----------------------------------------------------------------------------- public API
def body_panels(geometry: dict, cog, *, panel_size: float | None = None, subdivide: int = 1) -> Panels:
    """Quadrature points and area-weighted outward normals of a body's closed surface.

    Parameters
    ----------
    geometry : BemBody-style dict (:class:`mbcontrol.hydro.mesh.geometry.BemBody`), n-frame at
        rest, m: box, cylinder (axis x|y|z, with end caps), sphere, revolution (the whole
        profile revolved, closed by disks where r > 0 at the ends) or mesh (a CLOSED hull file
        read with ``capytaine.load_mesh``; z-up unless ``"axes": "ned"``; ``"center"`` offset).
    cog : CoG at rest, n-frame, m (3).
    panel_size : target cell edge, m. Default sqrt(surface area / 500) for primitives (580-750
        points for compact ones); for a mesh file, default its faces as they are, else each face
        is split into enough sub-triangles that their edges are <= panel_size.
    subdivide : s >= 1, s x s sub-cells per panel (s^2 sub-triangles per mesh triangle).

    Raises
    ------
    HydroError : bad geometry or settings, an unreadable mesh file, or one that is not closed.
    """
    kind = geometry.get("type") if isinstance(geometry, dict) else None
    if kind not in ("box", "sphere", "cylinder", "revolution", "mesh"):
        raise HydroError(f"body_panels: geometry.type = {kind!r}; expected 'box', 'cylinder', "
                         "'sphere', 'revolution' or 'mesh'")
    if not isinstance(subdivide, (int, np.integer)) or isinstance(subdivide, bool) or subdivide < 1:
        raise HydroError(f"body_panels: subdivide = {subdivide!r}; expected an int >= 1")
    try:
        if panel_size is not None and not (math.isfinite(float(panel_size)) and float(panel_size) > 0):
            raise ValueError("panel_size must be a finite length > 0 (m)")
        c = np.asarray(cog, dtype=float).reshape(3)
        if kind == "mesh":
            pts, nrm = _mesh_panels(geometry, panel_size, subdivide)
            return _frozen(pts - c[:, None], nrm)
        centre = np.asarray(geometry.get("center", (0.0, 0.0, 0.0)), dtype=float).reshape(3)
        pts, nrm = _primitive(kind, geometry, panel_size, subdivide)
    except HydroError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise HydroError(f"body_panels: geometry {geometry!r}, cog {cog!r}, panel_size {panel_size!r}: "
                         f"expected the fields of mbcontrol.hydro.mesh.geometry.BemBody.geometry, "
                         f"a 3-vector and a length > 0 ({exc})") from exc
    return _frozen(pts + (centre - c)[:, None], nrm)


def _mesh_panels(g: dict, panel_size, subdivide: int):
    """Points and normals of a closed mesh file, n-frame at rest (m)."""
    tri = _mesh_triangles(g)
    s = np.full(len(tri), subdivide)
    if panel_size is not None:                  # per face: sub-triangle edges <= panel_size
        edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
        s *= np.maximum(1, np.ceil(edges / float(panel_size) - 1e-9)).astype(int)
    pts, w = (np.vstack(a) for a in zip(*(_triangle_points(tri[s == k], k) for k in np.unique(s))))
    # a midpoint shared by two (sub-)triangles is one point carrying both weights
    key = np.round(pts / (1e-9 * np.abs(pts).max())).astype(np.int64)
    _, first, index = np.unique(key, axis=0, return_index=True, return_inverse=True)
    nrm = np.zeros((len(first), 3))
    np.add.at(nrm, index.ravel(), w)
    pts, nrm = pts[first].T, nrm.T
    _check_closed(g.get("file"), pts, nrm)
    return pts, nrm


def _primitive(kind: str, g: dict, panel_size, subdivide: int):
    """Points and normals of a box, sphere, cylinder or revolution about its centre."""
    if kind == "revolution" and (problem := profile_problem(g.get("profile"))) is not None:
        raise HydroError(f"body_panels: geometry.{problem[0]}: {problem[1]}")
    sizes = {"box": ["size"], "sphere": ["radius"], "cylinder": ["radius", "length"]}.get(kind, [])
    dims = [float(v) for name in sizes for v in np.ravel(g[name])]
    if len(dims) != (3 if kind == "box" else len(sizes)) or not all(math.isfinite(d) and d > 0 for d in dims):
        raise HydroError(f"body_panels: geometry {g!r}: expected {' and '.join(sizes)} finite > 0 "
                         "(m; a box size is 3 lengths)")
    if kind == "revolution":
        p = _closed(g["profile"])
        area = float(np.sum(math.pi * (p[:-1, 0] + p[1:, 0]) * np.hypot(*np.diff(p, axis=0).T)))
    else:
        d = dims + [0.0, 0.0]                          # sphere/cylinder: unused entries
        area = {"box": 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]), "sphere": 4 * math.pi * d[0] ** 2,
                "cylinder": 2 * math.pi * d[0] * (d[0] + d[1])}[kind]
    h = (float(panel_size) if panel_size is not None else math.sqrt(area / POINTS_TARGET)) / subdivide
    if kind == "box":
        return _box(dims, h)
    if kind == "sphere":
        return _sphere(dims[0], h)
    if kind == "cylinder":
        r, half = dims[0], dims[1] / 2
        pts, nrm = _revolved(np.array([[0.0, -half], [r, -half], [r, half], [0.0, half]]), h, even=True)
        turn = _AXES.get(g.get("axis", "z"))
        if turn is None:
            raise HydroError(f"body_panels: geometry.axis = {g.get('axis')!r}; expected 'x', 'y' or 'z'")
        return turn @ pts, turn @ nrm
    return _revolved(_closed(g["profile"]), h)


def _frozen(points: np.ndarray, normals: np.ndarray) -> Panels:
    arrays = [np.array(a, dtype=float, order="C") for a in (points, normals)]
    for a in arrays:
        a.setflags(write=False)                            # shared: Panels is frozen, so are they
    return Panels(*arrays)


def _is_casadi(*args) -> bool:
    return any(isinstance(a, (ca.SX, ca.MX, ca.DM)) for a in args)


def hydrostatic_pressure(rho, g, eta=0.0):
    """The callable p(x, y, z) = rho g max(z + eta, 0), Pa: calm water, or a uniform level
    ``eta`` (m, positive up: the surface is z = -eta). Elementwise on numpy arrays (np.maximum)
    or CasADi expressions (fmax); rho (kg/m^3), g (m/s^2) and eta may be CasADi scalars."""
    def pressure(x, y, z):
        depth = z + eta
        clip = ca.fmax if _is_casadi(depth) else np.maximum
        return (rho * g) * clip(depth, 0.0)
    return pressure


def pressure_wrench(panels: Panels, R, r_cog, pressure) -> tuple:
    """Force and moment of a pressure field on a posed body's closed surface.

    Parameters
    ----------
    panels : from :func:`body_panels`.
    R : rotation body -> n-frame (3x3), numpy or CasADi.
    r_cog : current CoG, n-frame, m (3), numpy or CasADi.
    pressure : callable p(x, y, z) -> Pa, elementwise on the n-frame positions of the points
        (numpy (N,) arrays, or CasADi 1 x N rows when R or r_cog is CasADi), zero where dry.

    Returns
    -------
    (force, moment): N, N m, n-frame, moment about the current CoG: -sum p_i R n_i and sum (R x_i)
    x (-p_i R n_i); numpy (3,) arrays or CasADi 3 x 1 (points as constants, ~15 flops each).
    """
    P, N = panels.points, panels.normals
    C = np.cross(P.T, N.T).T                               # x_i x n_i, body axes: moment = -R C p
    if _is_casadi(R, r_cog):
        R = R if _is_casadi(R) else ca.DM(np.asarray(R, dtype=float))
        r = ca.reshape(r_cog if _is_casadi(r_cog) else ca.DM(np.asarray(r_cog, float)), 3, 1)
        rows = [ca.DM(P[k:k + 1]) for k in range(3)]
        # n-frame coordinates as 1 x N rows; a coordinate the pressure ignores is dropped from
        # the compiled code (CasADi keeps only what the outputs depend on)
        x, y, z = (r[i] + R[i, 0] * rows[0] + R[i, 1] * rows[1] + R[i, 2] * rows[2] for i in range(3))
        p = pressure(x, y, z)
        f_body = ca.mtimes(ca.sparsify(ca.DM(N)), p.T)     # structural zeros: no work for them
        m_body = ca.mtimes(ca.sparsify(ca.DM(C)), p.T)
        return -ca.mtimes(R, f_body), -ca.mtimes(R, m_body)
    R = np.asarray(R, dtype=float).reshape(3, 3)
    X = np.asarray(r_cog, dtype=float).reshape(3, 1) + R @ P
    p = np.asarray(pressure(X[0], X[1], X[2]), dtype=float).reshape(-1)
    return -R @ (N @ p), -R @ (C @ p)
