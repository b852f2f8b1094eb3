"""Reader of WAMIT ``.out`` files (v6/v7 text output).

Format facts used here (WAMIT manual ch. 3-4; checked against rm3.out and sphere.out):

- Coefficients are non-dimensional: A_ij = Ā ρ L^k, B_ij = B̄ ρ ω L^k, C_ij = C̄ ρ g L^(k-1),
  X_i = X̄ ρ g A L^m, with L = "Length scale" (ULEN), k = 3, 4, 5 for translation-translation,
  mixed and rotation-rotation pairs and m = 2 (force) or 3 (moment).
- A(I,J), B(I,J), C(I,J): I is the force (mode on which the load acts), J the motion. The
  hydrostatic block shows it: C(4,6) = -ρgV x_b + m g x_g is printed while C(6,4) = 0 (a yaw turn
  of a body with its centre of buoyancy off the z axis makes a roll moment, not conversely).
  Modes of body n are 6(n-1)+1 .. 6n; entries WAMIT does not print are zero.
- "Wave period = infinite" is ω = 0 (A(0)); "Wave period = zero" is ω = ∞ (A(∞)).
- Phases (integer degrees) refer to the incident-wave elevation Re(A e^{iωt}) at X = Y = 0,
  i.e. the e^{+iωt} convention: the reader conjugates them for e^{-iωt}. Headings (deg) are
  measured from +X towards +Y in the z-up global frame, as Capytaine's wave_direction.
- XBODY/YBODY/ZBODY is the body origin (the point moments and rotations refer to) in global
  coordinates; centres of buoyancy and gravity are printed in body coordinates.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from mbcontrol.errors import HydroError

from .checks import clean
from .layout import body_name_list, build_dataset, dof_names

_F = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?|[-+]?(?:nan|NaN|NAN|inf|Inf|Infinity)"
_FLOAT = re.compile(_F)
_AB_ROW = re.compile(rf"^\s*(-?\d+)\s+(-?\d+)\s+({_F})(?:\s+({_F}))?\s*$")
_EX_ROW = re.compile(rf"^\s*(-?\d+)\s+({_F})\s+({_F})\s*$")
_EXCITATION = {"HASKIND EXCITING FORCES AND MOMENTS": "haskind",
               "DIFFRACTION EXCITING FORCES AND MOMENTS": "diffraction",
               "FROUDE-KRYLOV EXCITING FORCES AND MOMENTS": "froude_krylov",
               "SCATTERING EXCITING FORCES AND MOMENTS": "scattering"}


def _floats(text: str) -> list[float]:
    return [float(x.replace("D", "E").replace("d", "e")) for x in _FLOAT.findall(text)]


def _after_colon(line: str) -> list[float]:
    return _floats(line.split(":", 1)[1]) if ":" in line else []


class _Block:
    """One 'Wave period' block of the FORCE output."""

    def __init__(self, period: float):
        self.period = period
        self.A: dict = {}
        self.B: dict = {}
        self.has_ab = False
        self.exc: dict = {}  # kind -> {heading_deg: {mode: (mod, phase_deg)}}


def _read_lines(path: Path) -> list[str]:
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected a WAMIT .out file)")
    try:
        text = path.read_text(errors="strict")
    except (OSError, UnicodeDecodeError) as exc:
        raise HydroError(f"{path}: unreadable as a WAMIT .out text file ({type(exc).__name__}: {exc})") from exc
    if "WAMIT" not in text[:5000] and "Wave period" not in text:
        raise HydroError(f"{path}: not a WAMIT .out file (no 'WAMIT' header and no 'Wave period' blocks)")
    return text.splitlines()


def _parse_header_line(hdr: dict, s: str, n: int) -> None:
    if s.startswith("Gravity:"):
        v = _floats(s.split("Length scale:")[0])
        hdr["g"] = v[0] if v else None
        if "Length scale:" in s:
            hdr["ulen"] = (_floats(s.split("Length scale:")[1]) or [1.0])[0]
    elif s.startswith("Water depth:"):
        rest = s.split(":", 1)[1]
        hdr["depth"] = math.inf if "infinite" in rest.lower() else (_floats(rest) or [None])[0]
    elif "Irregular frequency index" in s:
        v = _floats(s.split("IRR", 1)[1])
        hdr["irr"].append(int(v[0]) if v else None)
    elif s.startswith("XBODY"):
        vals = dict(zip(("XBODY", "YBODY", "ZBODY", "PHIBODY"), [float(x) for x in re.findall(rf"=\s*({_F})", s)]))
        hdr["bodies"].append({"origin": [vals.get("XBODY", 0.0), vals.get("YBODY", 0.0), vals.get("ZBODY", 0.0)],
                              "phi": vals.get("PHIBODY", 0.0), "line": n + 1})
    elif hdr["bodies"]:
        b = hdr["bodies"][-1]
        for prefix, key in (("Volumes", "vol"), ("Center of Buoyancy", "cob"), ("C(3,3),C(3,4),C(3,5)", "c3"),
                            ("C(4,4),C(4,5),C(4,6)", "c4"), ("C(5,5),C(5,6)", "c5"), ("Center of Gravity", "cog")):
            if s.startswith(prefix):
                b[key] = _after_colon(s)
    if not hdr["bodies"]:  # GDF file names come before the body parameters
        m = re.search(r"Input from Geometric Data File:\s*(\S+)", s)
        if m is None and "Body number" not in s:
            m = re.match(r"N=\s*\d+\s+(\S+)$", s)
        if m and re.search(r"\.\w+$", m.group(1)):
            hdr["names"].append(re.sub(r"\.\w+$", "", Path(m.group(1)).name))


def _parse(lines: list[str], path: Path) -> dict:
    """Header data and one _Block per 'Wave period' block of the FORCE output."""
    hdr = {"g": None, "ulen": 1.0, "depth": None, "names": [], "bodies": [], "irr": []}
    blocks: list[_Block] = []
    cur, mode, kind, heading = None, None, None, None
    for n, line in enumerate(lines):
        s = line.strip()
        if s.startswith("Wave period"):
            head = s.split("Wavenumber")[0]
            if "infinite" in head:
                period = math.inf
            elif "zero" in head:
                period = 0.0
            else:
                v = _floats(head.split("=", 1)[1]) if "=" in head else []
                if not v:
                    raise HydroError(f"{path}:{n + 1}: cannot read the period in {s!r}")
                period = v[0]
            cur, mode, kind, heading = _Block(period), None, None, None
            blocks.append(cur)
            continue
        if cur is None:
            _parse_header_line(hdr, s, n)
            continue
        if not s or s.startswith("I ") or set(s) <= set("-* "):
            if s.startswith("*"):
                mode = None
            continue
        if mode == "ab":
            m = _AB_ROW.match(s)
            if m:
                i, j = abs(int(m.group(1))), abs(int(m.group(2)))
                cur.A[(i, j)] = float(m.group(3).replace("D", "E"))
                if m.group(4) is not None:
                    cur.B[(i, j)] = float(m.group(4).replace("D", "E"))
                continue
        elif mode == "exc":
            if s.startswith("Wave Heading"):
                v = _after_colon(s)
                heading = v[0] if v else None
                cur.exc[kind].setdefault(heading, {})
                continue
            m = _EX_ROW.match(s)
            if m and heading is not None:
                cur.exc[kind][heading][abs(int(m.group(1)))] = (float(m.group(2)), float(m.group(3)))
                continue
        if mode in ("ab", "exc") and re.match(r"^-?\d+\s", s):
            raise HydroError(f"{path}:{n + 1}: unreadable data row {s!r} in the block of period {cur.period} s; "
                             "expected mode indices and numbers")
        # any other text line is a section title: the ones read here, or one this reader skips
        if s.startswith("ADDED-MASS"):
            mode, cur.has_ab = "ab", True
        elif s in _EXCITATION:
            mode, kind, heading = "exc", _EXCITATION[s], None
            cur.exc.setdefault(kind, {})
        else:
            mode = None  # RAOs, drift forces, pressures, ...: skipped
    return {"hdr": hdr, "blocks": blocks}


def read_wamit(path, *, rho: float = 1000.0, g: float | None = None, body_names=None,
               excitation: str = "diffraction", **clean_kw):
    """Read a WAMIT ``.out`` file into the data-frame dataset (dimensional, e^{-iωt}, z up).

    Parameters
    ----------
    path : the ``.out`` file.
    rho : water density, kg/m^3 (WAMIT output does not contain it).
    g : gravity, m/s^2; None takes the file's "Gravity". A value different from the file's is
        an error: the non-dimensional data were computed with the file's g.
    body_names : one name per body (file order); default the GDF file names.
    excitation : "diffraction" (default) or "haskind": which WAMIT excitation to use; the other
        one is used, with a note, if the chosen one is absent.
    **clean_kw : options of :func:`mbcontrol.hydro.readers.clean`.

    ``reference_point`` is each body's XBODY origin; ``cog`` and ``center_of_buoyancy`` are
    converted from body to global coordinates. Bodies with PHIBODY != 0 are refused.
    """
    path = Path(path)
    src = f"WAMIT {path}"
    rho = float(rho)
    if not (math.isfinite(rho) and rho > 0):
        raise HydroError(f"{src}: rho = {rho!r}; expected a density > 0 (kg/m^3)")
    if excitation not in ("diffraction", "haskind"):
        raise HydroError(f"{src}: excitation = {excitation!r}; expected 'diffraction' or 'haskind'")
    parsed = _parse(_read_lines(path), path)
    hdr, blocks = parsed["hdr"], parsed["blocks"]
    notes = []
    bodies = hdr["bodies"]
    _check_bodies(src, bodies)
    g_file = hdr["g"]
    if g_file is None:
        raise HydroError(f"{src}: no 'Gravity:' line; expected the WAMIT header")
    if g is not None and abs(float(g) - g_file) > 1e-9 * g_file:
        raise HydroError(f"{src}: g = {g} differs from the file's Gravity {g_file}; the non-dimensional "
                         "coefficients were computed with the file's value — omit g or pass that value")
    g = float(g_file)
    L = float(hdr["ulen"])
    depth = hdr["depth"]
    if depth is None:
        raise HydroError(f"{src}: no 'Water depth:' line; expected the WAMIT header")
    nb = len(bodies)
    n = 6 * nb
    names, name_notes = body_name_list(hdr["names"], nb, body_names, path)
    notes += name_notes
    dofs = dof_names(names)
    if any(v is not None and v > 0 for v in hdr["irr"]):
        notes.append("WAMIT irregular-frequency removal was on (IRR > 0)")
    fin = [b for b in blocks if 0.0 < b.period < math.inf]
    if not fin:
        raise HydroError(f"{src}: missing frequencies: no 'Wave period (sec) =' blocks with coefficients")
    _check_modes(src, blocks, nb)
    w, A, B, A0, Ainf = _radiation(blocks, n, rho, L)
    exc, fk, diff, heads = _excitation(src, fin, n, rho, g, L, excitation, notes)
    K, vol, cob, ref, cog, awp = _hydrostatics(bodies, names, rho, g, L, notes)
    cog_arr = np.array(cog)
    notes.append("reference_point = XBODY origin of each body; cog and center_of_buoyancy converted from body "
                 "to global coordinates; waterplane_area = C(3,3)/(rho g)")
    ds = build_dataset(bodies=names, dofs=dofs, omega=w, A=A, B=B, K=K, exc=exc, headings=np.radians(heads),
                       A0=A0, Ainf=Ainf, fk=fk, diff=diff, volume=vol, cob=np.array(cob), ref=np.array(ref),
                       cog=None if np.isnan(cog_arr).any() else cog_arr, awp=awp, rho=rho, g=g, depth=depth,
                       source=src, notes=notes)
    ds.attrs["length_scale"] = L
    ds.attrs["original_time_convention"] = "exp(+i omega t) (WAMIT); excitation conjugated"
    return clean(ds, source=src, **clean_kw)


def _check_bodies(src: str, bodies: list) -> None:
    """Refuse a file without body parameters, a rotated body, incomplete hydrostatics."""
    if not bodies:
        raise HydroError(f"{src}: no body parameters (no 'XBODY =' line); expected a complete WAMIT .out file")
    for k, b in enumerate(bodies):
        if abs(b["phi"]) > 0:
            raise HydroError(f"{src}: body {k + 1} has PHIBODY = {b['phi']} deg (line {b['line']}); only bodies "
                             "whose axes are parallel to the global axes (PHIBODY = 0) are supported")
        for key, size in (("vol", 3), ("cob", 3), ("c3", 3), ("c4", 3), ("c5", 2)):
            if len(b.get(key, [])) < size:
                raise HydroError(f"{src}: body {k + 1}: hydrostatic data incomplete ({key}); "
                                 "expected Volumes, Center of Buoyancy and C(3,3)..C(5,6) lines")


def _check_modes(src: str, blocks: list, nb: int) -> None:
    """Every mode index of the coefficient and excitation blocks is one of the bodies' 6 nb."""
    n = 6 * nb
    for b in blocks:
        bad = [ij for ij in list(b.A) + list(b.B) if max(ij) > n or min(ij) < 1]
        if bad:
            raise HydroError(f"{src}: wrong DOF count: mode index {max(max(ij) for ij in bad)} in the block of "
                             f"period {b.period} s, but the file has {nb} bod(y/ies) = {n} modes")
        for kind, per_h in b.exc.items():
            modes = [i for d in per_h.values() for i in d]
            if modes and (max(modes) > n or min(modes) < 1):
                raise HydroError(f"{src}: wrong DOF count: {kind} excitation mode {max(modes)} in the block of "
                                 f"period {b.period} s, but the file has {nb} bod(y/ies) = {n} modes")


def _rotational(n: int) -> np.ndarray:
    """1 for a rotational mode, 0 for a translational one."""
    return np.array([(k % 6) >= 3 for k in range(n)], dtype=int)


def _radiation(blocks: list, n: int, rho: float, L: float):
    """(ω rad/s, A, B at the finite periods, A(0), A(∞)), dimensional (B missing: nan)."""
    rot = _rotational(n)
    kmat = 3 + rot[:, None] + rot[None, :]          # L exponent of A, B

    def matrix(d: dict, scale) -> np.ndarray:
        M = np.zeros((n, n))
        for (i, j), v in d.items():
            M[i - 1, j - 1] = v
        return M * scale
    zero = [b for b in blocks if b.period == math.inf]
    inf = [b for b in blocks if b.period == 0.0]
    fin = [b for b in blocks if 0.0 < b.period < math.inf]
    w = np.array([2 * math.pi / b.period for b in fin])
    A = np.full((len(fin), n, n), np.nan)
    B = np.full((len(fin), n, n), np.nan)
    for k, b in enumerate(fin):
        if b.has_ab:
            A[k] = matrix(b.A, rho * L ** kmat)
            B[k] = matrix(b.B, rho * w[k] * L ** kmat)
            if not b.B:
                B[k] = np.nan  # an added-mass-only block: damping missing
    A0 = matrix(zero[-1].A, rho * L ** kmat) if zero and zero[-1].A else None
    Ainf = matrix(inf[-1].A, rho * L ** kmat) if inf and inf[-1].A else None
    return w, A, B, A0, Ainf


def _excitation(src: str, fin: list, n: int, rho: float, g: float, L: float, excitation: str, notes: list):
    """(excitation, Froude-Krylov, scattering wrenches (headings, ω, modes) or None, headings deg),
    e^{-iωt}, from the chosen WAMIT excitation (the other one, noted, when it is absent)."""
    mvec = 2 + _rotational(n)                        # L exponent of X
    kinds = {k for b in fin for k in b.exc}
    chosen = excitation if excitation in kinds else ("haskind" if excitation == "diffraction" else "diffraction")
    if chosen not in kinds:
        raise HydroError(f"{src}: no DIFFRACTION or HASKIND EXCITING FORCES blocks; expected excitation data")
    if chosen != excitation:
        notes.append(f"{excitation} excitation not in the file; used {chosen}")
    notes.append(f"excitation_force from WAMIT's {chosen.upper()} EXCITING FORCES (phases printed in whole degrees)")
    heads = sorted({h for b in fin for h in b.exc.get(chosen, {})})

    def wrench(kind: str):
        X = np.full((len(heads), len(fin), n), np.nan, dtype=complex)
        for k, b in enumerate(fin):
            for ih, h in enumerate(heads):
                rows = b.exc.get(kind, {}).get(h)
                if rows is None:
                    continue
                X[ih, k, :] = 0.0
                for i, (mod, ph) in rows.items():
                    # e^{+iωt} -> e^{-iωt}: complex conjugate
                    X[ih, k, i - 1] = mod * np.exp(-1j * math.radians(ph)) * rho * g * L ** mvec[i - 1]
        return X
    fk = wrench("froude_krylov") if "froude_krylov" in kinds else None
    diff = wrench("scattering") if "scattering" in kinds else None
    if fk is not None:
        notes.append("froude_krylov_force / diffraction_force from WAMIT's FROUDE-KRYLOV / SCATTERING blocks")
    return wrench(chosen), fk, diff, heads


def _hydrostatics(bodies: list, names: list, rho: float, g: float, L: float, notes: list):
    """(K force-first, volumes, centres of buoyancy, reference points, CoGs (nan: absent),
    waterplane areas) of the bodies, dimensional and global."""
    n = 6 * len(bodies)
    rot = _rotational(n)
    cmat = 2 + rot[:, None] + rot[None, :]          # L exponent of C
    K = np.zeros((n, n))
    vol, cob, ref, cog, awp = [], [], [], [], []
    for k, b in enumerate(bodies):
        o = 6 * k
        c33, c34, c35 = b["c3"][:3]
        c44, c45, c46 = b["c4"][:3]
        c55, c56 = b["c5"][:2]
        C = np.zeros((6, 6))  # force-first; WAMIT prints C(6,4) = C(6,5) = 0 implicitly
        C[2, 2], C[2, 3], C[2, 4] = c33, c34, c35
        C[3, 2], C[4, 2] = c34, c35
        C[3, 3], C[3, 4], C[3, 5] = c44, c45, c46
        C[4, 3], C[4, 4], C[4, 5] = c45, c55, c56
        K[o:o + 6, o:o + 6] = C * rho * g * L ** cmat[:6, :6]
        origin = np.asarray(b["origin"], dtype=float)
        v = np.asarray(b["vol"][:3], dtype=float)
        if np.ptp(v) > 1e-3 * np.abs(v).mean():
            notes.append(f"body {names[k]}: VOLX, VOLY, VOLZ = {v.tolist()} differ by more than 0.1 %; used the mean")
        vol.append(float(v.mean()))
        cob.append(origin + np.asarray(b["cob"][:3], dtype=float))
        ref.append(origin)
        cog.append(origin + np.asarray(b["cog"][:3], dtype=float) if len(b.get("cog", [])) >= 3 else
                   np.full(3, np.nan))
        awp.append(c33 * L ** 2)
    return K, vol, cob, ref, cog, awp
