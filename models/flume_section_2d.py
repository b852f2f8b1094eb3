#!/usr/bin/env python3
"""2-D hydrodynamics of the flume section (models/flume_section.toml) from a 3-D BEM.

The section spans the 0.6 m flume (7 mm gaps to the walls), so the flow around it is 2-D and
what it feels is the 2-D (strip) coefficient per metre times its 0.586 m span. Capytaine
solves 3-D bodies; a prism of length L has end effects e(L) at its two ends:
X(L) = L x_2D + 2 e(L). The difference of two long prisms cancels them,
x_2D ~ (X(L2) - X(L1)) / (L2 - L1), and the difference of the next pair shows how far that
has converged. This script meshes the rounded-bilge section (beam 0.40 m, draft 0.20 m, bilge
radius 0.0512 m) as prisms of LENGTHS metres, solves sway, heave and roll about the CoG (0.094 m
below the surface) and beam-sea diffraction in 1.0 m of water with mbcontrol.hydro.compute
(lids against irregular frequencies, results cached), and writes:

- models/flume_section_hydro.nc: the scene's hydro file (NED body frame at the CoG, per the
  0.586 m span), from the two longest prisms;
- with --report FILE.json: the strip values per pair of lengths at the test frequencies, for
  the convergence table.

Heave excitation from the Haskind relation. For a 2-D body symmetric about its centre plane the
radiation damping and the excitation of a DOF are tied, in any depth, by
B_ii = |X_i|^2 / (2 rho g c_g) per metre (the energy radiated to both sides). The strip values
of sway and roll satisfy it within 3 % from 4 to 11 rad/s (`--report` lists the ratios), but
those of heave do not: the ratio falls from 0.93 at 5 rad/s to 0.57 at 8.6 and 0.30 at 9.3
(the symmetric, heave-like interior modes of a long prism make its diffraction solution the
weak one, and the mesh was sized for 7 rad/s). The heave excitation written is therefore
|X_3| = sqrt(2 rho g c_g L B_33) with the BEM's phase (L the span), up to 9.3 rad/s where the
BEM's B_33 stops falling (above it, where both are unreliable, the 9.3 rad/s correction is held:
no tank run is there); the measured heave
amplitudes above 7 rad/s side with it (tank runs 4101-4131, 6101-6121: measured / modelled
1.05-2.1 with the BEM's X_3, matching its Haskind ratio's -1/2 power).

Hydrostatics are the measured ones, not the meshed: heave rho g B L_span (the waterline is
vertical-sided), roll m g GM with the heel test's GM 0.0629 m and m 46.8 kg, and the
displaced volume m / rho (the section floats at rest on the rig, which has no vertical
spring).

    python models/flume_section_2d.py                  # ~15 min on one core
    python models/flume_section_2d.py --lengths 2 3 --omega-count 4 --panel 0.05   # a quick look
    python models/flume_section_2d.py --haskind-only    # redo only the post-processing steps
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

if __name__ == "__main__":      # run as a script from a checkout: the package beside models/
    sys.path.append(str(Path(__file__).resolve().parent.parent))   # (an installed one wins)

HERE = Path(__file__).resolve().parent
BEAM, DRAFT, BILGE = 0.40, 0.20, 0.0512       # m
SPAN = 0.586                                  # m, the section's length across the flume
MASS, GM, KG = 46.8, 0.0629, 0.106            # kg, m (heel test), m above the keel
AXLE_MASS = 0.05                              # kg of MASS that heaves but does not roll (scene)
RHO, G, DEPTH = 1000.0, 9.81, 1.0
TEST_OMEGAS = (4.143, 4.952, 5.075, 5.194, 5.311, 5.425, 5.646, 5.860, 6.065, 7.004, 7.830,
               8.578, 9.265, 9.905)           # rad/s, the tank runs
BEAM_SEAS = math.pi / 2                       # NED heading: waves travel along +y
COG_Z = DRAFT - KG                            # m below the surface (NED z)
LID_PANEL = 0.1                               # m, lid panels (irregular frequencies only)


def profile(panel: float) -> np.ndarray:
    """(y, z) points (z up) of the immersed section, waterline to waterline, about panel m apart."""
    r, half = BILGE, BEAM / 2

    def line(a, b):
        n = max(1, int(math.ceil(math.dist(a, b) / panel)))
        return [tuple(np.add(a, np.multiply(np.subtract(b, a), k / n))) for k in range(n)]

    def arc(centre, start, stop):
        n = max(2, int(math.ceil(r * abs(stop - start) / panel)))
        return [(centre[0] + r * math.cos(a), centre[1] + r * math.sin(a))
                for a in np.linspace(start, stop, n, endpoint=False)]

    pts = line((-half, 0.0), (-half, -DRAFT + r))
    pts += arc((-half + r, -DRAFT + r), math.pi, 1.5 * math.pi)
    pts += line((-half + r, -DRAFT), (half - r, -DRAFT))
    pts += arc((half - r, -DRAFT + r), 1.5 * math.pi, 2 * math.pi)
    pts += line((half, -DRAFT + r), (half, 0.0)) + [(half, 0.0)]
    return np.array(pts)


def prism_mesh(length: float, panel: float, panel_x: float):
    """Capytaine mesh (z up) of the immersed prism: the profile extruded along x, end caps fanned
    from the section's centroid; normals out of the body."""
    import capytaine as cpt
    yz = profile(panel)
    xs = np.linspace(-length / 2, length / 2, max(2, int(math.ceil(length / panel_x))) + 1)
    n = len(yz)
    vertices = [(x, y, z) for x in xs for y, z in yz]
    faces = [[i * n + k, i * n + k + 1, (i + 1) * n + k + 1, (i + 1) * n + k]
             for i in range(len(xs) - 1) for k in range(n - 1)]
    centre = (0.0, float(yz[:, 1].mean()))
    for end, x in ((0, xs[0]), (len(xs) - 1, xs[-1])):
        c = len(vertices)
        vertices.append((x, *centre))
        for k in range(n - 1):
            a, b = end * n + k, end * n + k + 1
            faces.append([c, a, b, b] if end else [c, b, a, a])
    mesh = cpt.Mesh(np.array(vertices), np.array(faces), name=f"section_L{length:g}")
    if mesh.volume < 0:                       # faces wound the other way: flip them all
        mesh = cpt.Mesh(np.array(vertices), np.array(faces)[:, ::-1], name=mesh.name)
    return mesh


def solve(length: float, omegas, panel: float, panel_x: float, progress: bool):
    """mbcontrol.hydro.compute of the prism of `length` m (NED body frame at the CoG)."""
    from mbcontrol.cache import cache_dir
    from mbcontrol.hydro import BemBody, compute
    mesh = prism_mesh(length, panel, panel_x)
    folder = Path(tempfile.mkdtemp(prefix="flume2d_"))
    path = folder / f"section_L{length:g}.gdf"
    write_gdf(mesh, path)
    volume = abs(mesh.volume)
    # panel_size sizes the lid (the hull is the mesh above): coarser than the hull is enough
    body = BemBody(name="section", geometry={"type": "mesh", "file": str(path), "axes": "z_up"},
                   cog=(0.0, 0.0, COG_Z), mass=RHO * volume, panel_size=LID_PANEL,
                   dofs=("Sway", "Heave", "Roll"))
    return compute([body], rho=RHO, g=G, depth=DEPTH, omegas=np.asarray(omegas, float),
                   headings=(BEAM_SEAS,), cache_dir=cache_dir(), progress=progress)


def write_gdf(mesh, path: Path) -> None:
    """WAMIT GDF file (z up, no symmetry flags) of a Capytaine mesh: four vertices a panel."""
    lines = ["flume section prism (models/flume_section_2d.py)", f"1.0 {G}", "0 0",
             str(mesh.nb_faces)]
    for face in mesh.faces:
        lines += [" ".join(f"{v:.9e}" for v in mesh.vertices[k]) for k in face]
    path.write_text("\n".join(lines) + "\n")


STRIP_VARS = ("added_mass", "radiation_damping", "added_mass_inf", "excitation_force",
              "froude_krylov_force", "diffraction_force")


def strip(short, long, l_short: float, l_long: float):
    """Per metre: (X(L2) - X(L1)) / (L2 - L1) of the frequency-dependent coefficients."""
    out = long.copy()
    for var in STRIP_VARS:
        if var in long:
            out[var] = (long[var] - short[var]) / (l_long - l_short)
    return out


def span_dataset(per_metre):
    """The scene's hydro file: per-metre coefficients times the span, measured hydrostatics."""
    ds = per_metre.copy()
    for var in STRIP_VARS:
        if var in ds:
            ds[var] = ds[var] * SPAN
    dofs = [str(d) for d in ds["radiating_dof"].values]
    K = np.zeros((len(dofs), len(dofs)))
    K[dofs.index("section__Heave"), dofs.index("section__Heave")] = RHO * G * BEAM * SPAN
    K[dofs.index("section__Roll"), dofs.index("section__Roll")] = MASS * G * GM
    ds["hydrostatic_stiffness"] = (("radiating_dof", "influenced_dof"), K)
    ds["hydrostatic_stiffness"].attrs["units"] = per_metre["hydrostatic_stiffness"].attrs.get("units", "")
    ds["displaced_volume"] = (("body",), np.array([MASS / RHO]))
    # the scene's `section` body: the floating 46.8 kg less the axle, a body of its own there
    ds["mass"] = (("body",), np.array([MASS - AXLE_MASS]))
    if "waterplane_area" in ds:
        ds["waterplane_area"] = (("body",), np.array([BEAM * SPAN]))
    if "added_mass_zero" in ds:
        ds["added_mass_zero"] = ds["added_mass_zero"] * np.nan
        ds["added_mass_zero"].attrs["note"] = "NaN: not a strip quantity here"
    notes = list(ds.attrs.get("notes", []))
    notes.append(f"2-D strip coefficients times the {SPAN} m span: Capytaine prisms of "
                 f"{ds.attrs['prism_lengths']} m differenced in length (end effects cancel); "
                 f"hydrostatics measured: heave rho g B span, roll m g GM (GM {GM} m, "
                 f"m {MASS} kg), displaced volume m / rho")
    ds.attrs.update(source="models/flume_section_2d.py (Capytaine, length differencing)",
                    notes=notes)
    return ds


def haskind_ratio(ds, dof: str) -> np.ndarray:
    """|X|^2 / (2 rho g c_g L B) per frequency for one DOF of the span dataset (1 when the
    excitation and the radiation damping agree)."""
    from mbcontrol.waves import group_velocity
    d = f"section__{dof}"
    X = ds["excitation_force"].sel(influenced_dof=d).isel(wave_direction=0)
    X = X.sel(complex="re").values + 1j * X.sel(complex="im").values if "complex" in X.dims \
        else X.values
    B = ds["radiation_damping"].sel(radiating_dof=d, influenced_dof=d).values
    cg = np.array([group_velocity(w, DEPTH, G) for w in ds["omega"].values])
    return np.abs(X) ** 2 / (2 * RHO * G * cg * SPAN * B)


def heave_excitation_from_damping(ds):
    """The dataset with |X_heave| = sqrt(2 rho g c_g L B_33) (phase kept): see the docstring."""
    import xarray as xr
    if ds.attrs.get("heave_excitation") == "haskind":
        return ds
    ds = ds.copy(deep=True)
    ratio = haskind_ratio(ds, "Heave")
    # above the first minimum of B33 past 6 rad/s the BEM's heave damping rises again, which a
    # 2-D heave damping never does: hold the correction there instead of following it
    omega = ds["omega"].values
    B33 = ds["radiation_damping"].sel(radiating_dof="section__Heave",
                                      influenced_dof="section__Heave").values
    rising = np.flatnonzero((omega[1:] > 6.0) & (np.diff(B33) > 0))
    if rising.size:
        ratio[rising[0] + 1:] = ratio[rising[0]]
    sel = dict(influenced_dof="section__Heave")
    scale = xr.DataArray(1.0 / np.sqrt(ratio), coords={"omega": ds["omega"]}, dims="omega")
    ds["excitation_force"].loc[sel] = ds["excitation_force"].loc[sel] * scale
    notes = list(ds.attrs.get("notes", []))
    notes.append("heave excitation magnitude from the Haskind relation |X3| = sqrt(2 rho g c_g "
                 "L B33), BEM phase kept (the BEM's own ratio: "
                 + ", ".join(f"{w:.2f}: {r:.2f}" for w, r in
                             zip(ds["omega"].values[::6], ratio[::6])) + ")")
    ds.attrs.update(notes=notes, heave_excitation="haskind")
    return ds


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--lengths", type=float, nargs="+", default=[2.0, 4.0, 6.0],
                        help="prism lengths, m (ascending; the last two make the file)")
    parser.add_argument("--panel", type=float, default=0.025,
                        help="panel size around the section, m (default 0.025)")
    parser.add_argument("--panel-x", type=float, default=0.1,
                        help="panel length along the prism, m (default 0.1)")
    parser.add_argument("--omega-count", type=int, default=30,
                        help="frequencies from 1.5 to 14 rad/s besides the 14 test ones")
    parser.add_argument("--out", default=str(HERE / "flume_section_hydro.nc"))
    parser.add_argument("--report", help="write the strip values per length pair as JSON")
    parser.add_argument("--haskind-only", action="store_true",
                        help="only redo the post-processing (section mass, heave Haskind step) "
                        "on the existing --out file")
    args = parser.parse_args(argv)
    from mbcontrol.hydro import read_netcdf, write_netcdf_atomic
    if args.haskind_only:
        ds = read_netcdf(Path(args.out))
        ds["mass"] = (("body",), np.array([MASS - AXLE_MASS]))
        ds = heave_excitation_from_damping(ds)
        write_netcdf_atomic(ds, Path(args.out))
        print(f"wrote {args.out}", file=sys.stderr)
        return 0
    lengths = sorted(args.lengths)
    omegas = np.unique(np.round(np.concatenate([np.linspace(1.5, 14.0, args.omega_count),
                                                TEST_OMEGAS]), 6))
    data = {}
    for length in lengths:
        print(f"prism L = {length:g} m ...", file=sys.stderr, flush=True)
        data[length] = solve(length, omegas, args.panel, args.panel_x, progress=True)
    pairs = list(zip(lengths[:-1], lengths[1:]))
    strips = {p: strip(data[p[0]], data[p[1]], *p) for p in pairs}
    best = strips[pairs[-1]]
    best.attrs["prism_lengths"] = f"{pairs[-1][0]:g} and {pairs[-1][1]:g}"
    write_netcdf_atomic(heave_excitation_from_damping(span_dataset(best)), Path(args.out))
    print(f"wrote {args.out}", file=sys.stderr)
    if args.report:
        report = {"omega": [float(w) for w in TEST_OMEGAS], "pairs": {}}
        for (a, b), ds in strips.items():
            sel = ds.sel(omega=list(TEST_OMEGAS), method="nearest")
            entry = {}
            for dof in ("Sway", "Heave", "Roll"):
                d = f"section__{dof}"
                entry[dof] = {
                    "added_mass": sel["added_mass"].sel(radiating_dof=d, influenced_dof=d).values.tolist(),
                    "radiation_damping": sel["radiation_damping"].sel(radiating_dof=d, influenced_dof=d).values.tolist(),
                    "excitation_abs": np.abs(sel["excitation_force"].sel(influenced_dof=d).values).ravel().tolist()}
            report["pairs"][f"{a:g}-{b:g}"] = entry
        Path(args.report).write_text(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
