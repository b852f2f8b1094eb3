"""Tests of mbcontrol.hydro.readers: Capytaine .nc and BEMIO .h5 files, dispatch by format,
cleaning (checks, damping) and bad data.

A Capytaine run (mbcontrol.hydro.compute) of WEC-Sim's R = 5 m hemisphere is compared with its
WAMIT file in NED body frames, so time convention, heading and frame signs are tested end to
end. Bad data are small corrupted copies written to tmp_path.
"""
from __future__ import annotations

import logging
import math
import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from mbcontrol.errors import HydroError
from mbcontrol.hydro import BemBody, compute, write_netcdf_atomic
from mbcontrol.hydro.readers import (HydroCleaningWarning, clean, read_bemio, read_capytaine,
                                     read_hydro, read_wamit, to_scene_frames)
from tests.helpers.reader_data import DATA, R_SPHERE, RHO, SPHERE, WAVESTAR, _m

if not SPHERE.exists():
    pytest.skip(f"reference data not found in {DATA}", allow_module_level=True)


# ------------------------------------------------------------------ cross-reader consistency
W_CROSS = np.array([0.4, 0.7, 1.0, 1.3, 1.6, 2.0])  # on the file's 0.05 rad/s grid, kR = 0.08..2


@pytest.fixture(scope="module")
def hemisphere_capytaine():
    body = BemBody(name="sphere", geometry={"type": "sphere", "radius": R_SPHERE, "center": [0, 0, 0]},
                   cog=(0.0, 0.0, 0.0), mass=RHO * 2 / 3 * math.pi * R_SPHERE**3, panel_size=0.7, dofs=("Heave",))
    return compute([body], rho=RHO, g=9.81, depth=np.inf, omegas=W_CROSS, progress=False)


def test_wamit_sphere_agrees_with_capytaine_in_body_frames(sphere, hemisphere_capytaine):
    cp = hemisphere_capytaine
    wb = to_scene_frames(sphere, {"sphere": [0.0, 0.0, 0.0]}).sel(omega=W_CROSS, method="nearest")
    assert np.allclose(wb["omega"].values, W_CROSS, rtol=1e-6)  # the WAMIT grid holds these ω (7 digits)
    d = "sphere__Heave"
    A_w, A_c = _m(wb, "added_mass", d, d), _m(cp, "added_mass", d, d)
    B_w, B_c = _m(wb, "radiation_damping", d, d), _m(cp, "radiation_damping", d, d)
    X_w = _m(wb, "excitation_force", d, wave_direction=0.0)
    X_c = _m(cp, "excitation_force", d, wave_direction=0.0)
    # Mesh tolerance: Capytaine at 0.7 m panels (552 hull panels) vs WAMIT's 14400 panels. Measured at
    # 1.0 / 0.7 / 0.5 m panels: A +2.7 / +2.2 / +1.7 %, B +3.6 / +1.6 / +1.3 %, |X| 2.2 / 1.1 / 1.0 %,
    # phase 1.8 / 1.3 / 0.9 deg, all shrinking ~linearly with panel size towards WAMIT: 3 % and 2 deg
    # (the latter includes WAMIT's whole-degree phase printing, ±0.5 deg).
    np.testing.assert_allclose(A_c, A_w, rtol=3e-2)
    np.testing.assert_allclose(B_c, B_w, rtol=3e-2)
    np.testing.assert_allclose(np.abs(X_c), np.abs(X_w), rtol=3e-2)
    assert np.max(np.abs(np.degrees(np.angle(X_c / X_w)))) < 2.0
    # Without the conjugation the WAMIT phases would differ by twice theirs: 8 to 186 deg here.
    assert np.max(np.abs(np.degrees(np.angle(X_c / np.conj(X_w))))) > 8.0
    # Long-wave sign in NED body frames: an upward force is negative heave (phase ≈ 180 deg at ω = 0.4)
    assert X_w[0].real < 0 and X_c[0].real < 0
    # ω = 0 and ∞ limits: Capytaine's direct solves vs WAMIT's blocks, same mesh tolerance (measured 1.8, 2.7 %)
    assert float(_m(cp, "added_mass_zero", d, d)) == pytest.approx(float(_m(wb, "added_mass_zero", d, d)), rel=3e-2)
    assert float(_m(cp, "added_mass_inf", d, d)) == pytest.approx(float(_m(wb, "added_mass_inf", d, d)), rel=4e-2)


def test_mbcontrol_file_round_trip(tmp_path, hemisphere_capytaine):
    # A compute() output (NED body frames at the CoG) saved by write_netcdf_atomic is read back into
    # the data frame (reference point = CoG) and to_scene_frames at the same CoG reproduces it exactly.
    path = write_netcdf_atomic(hemisphere_capytaine, tmp_path / "hemi.nc")
    data = read_hydro(path)
    assert data.attrs["source"].startswith("mbcontrol ")
    np.testing.assert_allclose(data["reference_point"].values, [[0.0, 0.0, 0.0]])
    d = "sphere__Heave"  # the data frame is z up: heave excitation back to +ρgA_wp-like sign
    assert _m(data, "excitation_force", d, wave_direction=0.0)[0].real > 0
    back = to_scene_frames(data, {"sphere": [0.0, 0.0, 0.0]})
    for v in ("added_mass", "radiation_damping", "added_mass_inf", "added_mass_zero", "excitation_force",
              "hydrostatic_stiffness", "center_of_buoyancy"):
        np.testing.assert_array_equal(back[v].transpose(*hemisphere_capytaine[v].dims).values,
                                      hemisphere_capytaine[v].values)  # T is ±1 entries: exact
    np.testing.assert_array_equal(back["wave_direction"].values, hemisphere_capytaine["wave_direction"].values)
    # A reader's output saved the same way reads back unchanged (attrs notes/cleaning included)
    again = read_hydro(write_netcdf_atomic(data, tmp_path / "data.nc"))
    for v in data.data_vars:
        np.testing.assert_array_equal(again[v].values, data[v].values)
    assert again.attrs["cleaning"] == data.attrs["cleaning"] and again.attrs["notes"][:len(data.attrs["notes"])] \
        == data.attrs["notes"]


def _capytaine_export(path, rotation_center, name="hemi.a"):
    import capytaine as cpt

    mesh = cpt.mesh_sphere(radius=1.0, center=(0, 0, 0), resolution=(8, 16)).immersed_part()
    vol = mesh.volume
    body = cpt.FloatingBody(mesh=mesh, dofs=cpt.rigid_body_dofs(rotation_center=rotation_center),
                            center_of_mass=(0.0, 0.0, -0.3), mass=RHO * vol, name=name)
    test = xr.Dataset(coords={"omega": [0.0, 0.3, 1.0, 2.0, 3.0, np.inf], "wave_direction": [0.0, np.pi / 4],
                              "radiating_dof": ["Heave", "Surge", "Pitch", "Sway", "Roll", "Yaw"],
                              "water_depth": [np.inf], "rho": [RHO], "g": [9.81]})
    logging.getLogger("capytaine").setLevel(logging.ERROR)
    ds = cpt.BEMSolver().fill_dataset(test, body, progress_bar=False)
    cpt.export_dataset(str(path), ds)
    return ds


def test_capytaine_export_read_and_shift_end_to_end(tmp_path):
    # Two Capytaine runs of one coarse hemisphere (R = 1 m, 128 panels), rotation centre at z = -0.5
    # and at the CoG z = -0.3; both exported with capytaine.export_dataset. Read, then mapped to the
    # CoG with to_scene_frames, they must agree to round-off: the reference-point shift is exact
    # for rigid modes (the mass equals ρ × mesh volume, so the hydrostatics are in equilibrium too).
    ref_a = _capytaine_export(tmp_path / "a.nc", (0.0, 0.0, -0.5))
    _capytaine_export(tmp_path / "b.nc", (0.0, 0.0, -0.3))
    a, b = read_capytaine(tmp_path / "a.nc"), read_capytaine(tmp_path / "b.nc")
    assert list(a["body"].values) == ["hemi_a"] and a["radiating_dof"].values[2] == "hemi_a__Heave"
    np.testing.assert_allclose(a["reference_point"].values, [[0.0, 0.0, -0.5]])
    np.testing.assert_allclose(a["cog"].values, [[0.0, 0.0, -0.3]])
    assert list(a["omega"].values) == [0.3, 1.0, 2.0, 3.0]  # ω = 0, ∞ moved to A(0), A(∞)
    # The reader keeps Capytaine's values (no conjugation; influenced = force): same numbers.
    assert complex(_m(a, "excitation_force", "hemi_a__Surge", omega=1.0, wave_direction=0.0)) == complex(
        ref_a["excitation_force"].sel(omega=1.0, wave_direction=0.0, influenced_dof="Surge"))
    assert float(_m(a, "added_mass_inf", "hemi_a__Heave", "hemi_a__Heave")) == pytest.approx(
        float(ref_a["added_mass"].sel(omega=np.inf, influenced_dof="Heave", radiating_dof="Heave")), rel=1e-12)
    # Capytaine's own long-wave phase of surge vs heave is -90 deg (kR = 0.009 at 0.3 rad/s): the
    # sign the WAMIT and BEMIO readers produce after conjugation (test above). Within 1 deg.
    F = a["excitation_force"].sel(omega=0.3, wave_direction=0.0)
    assert math.degrees(np.angle(complex(F.sel(influenced_dof="hemi_a__Surge")) /
                                 complex(F.sel(influenced_dof="hemi_a__Heave")))) == pytest.approx(-90.0, abs=1.0)
    cog = {"hemi_a": [0.0, 0.0, 0.3]}  # NED
    sa, sb = to_scene_frames(a, cog), to_scene_frames(b, cog)
    for v in ("added_mass", "radiation_damping", "added_mass_inf", "added_mass_zero", "excitation_force",
              "hydrostatic_stiffness"):
        x, y = sa[v].values, sb[v].values
        assert np.abs(x - y).max() < 1e-9 * np.abs(y).max(), v  # round-off of two BEM solves (~1e-16 measured)


# ------------------------------------------------------------------ BEMIO
def test_bemio_equals_stored_values_times_documented_factors(wavestar):
    import h5py

    with h5py.File(WAVESTAR, "r") as f:
        w = f["simulation_parameters/w"][:, 0]
        rho, g = float(f["simulation_parameters/rho"][0, 0]), float(f["simulation_parameters/g"][0, 0])
        hc = f["body1/hydro_coeffs"]
        A = np.moveaxis(hc["added_mass/all"][()], -1, 0)            # (ω, force, motion)
        B = np.moveaxis(hc["radiation_damping/all"][()], -1, 0)
        Ainf, C = hc["added_mass/inf_freq"][()], hc["linear_restoring_stiffness"][()]
        X = np.transpose(hc["excitation/re"][()] + 1j * hc["excitation/im"][()], (1, 2, 0))  # (β, ω, dof)
        cg = f["body1/properties/cg"][()].reshape(-1)
    assert (rho, g) == (1000.0, 9.80665)  # simulation_parameters of the file
    keep = w <= 10.0
    sym = lambda x: 0.5 * (x + np.swapaxes(x, -1, -2))  # noqa: E731  clean() symmetrises (asymmetry 1e-5)
    ff = lambda v: wavestar[v].transpose(..., "influenced_dof", "radiating_dof").values  # noqa: E731
    # BEMIO/WAMIT normalisation: A/ρ, B/(ρω), C/(ρg), X/(ρg); only round-off may differ: rtol 1e-12.
    np.testing.assert_allclose(ff("added_mass"), sym(A[keep]) * rho, rtol=1e-12)
    np.testing.assert_allclose(ff("radiation_damping"), sym(B[keep]) * rho * w[keep, None, None], rtol=1e-12,
                               atol=1e-15)
    np.testing.assert_allclose(ff("added_mass_inf"), sym(Ainf) * rho, rtol=1e-12)
    np.testing.assert_allclose(ff("hydrostatic_stiffness"), C * rho * g, rtol=1e-12)
    np.testing.assert_allclose(wavestar["excitation_force"].values, np.conj(X[:, keep, :]) * rho * g, rtol=1e-12)
    np.testing.assert_allclose(wavestar["reference_point"].values[0], cg)  # data refer to BEMIO's cg
    assert wavestar.attrs["depth"] == 0.65 and np.all(np.isnan(wavestar["added_mass_zero"].values))
    assert any("added_mass_zero" in n for n in wavestar.attrs["notes"])


def test_bemio_full_range_is_symmetrised_with_a_warning_and_repairs_irregular_spikes():
    # Above ~15 rad/s (wavelengths under ~0.3 m, the float's size) wavestar.h5 loses reciprocity
    # (0.16 % in A and 0.81 % in B at 23.4 rad/s, scaled: within a panel solution's own error, BEM_ASYM_TOL 1 %)
    # and has isolated negative-damping spikes (irregular frequencies, 35.6 rad/s and up):
    # symmetrised with a warning that names the size, repaired, every change listed.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = read_bemio(WAVESTAR)
    texts = [str(c.message) for c in caught if issubclass(c.category, HydroCleaningWarning)]
    assert any(re.search(r"wavestar\.h5: added_mass is not symmetric: relative asymmetry 0.00156 > 0.001 "
                         r"at Float__Surge / Float__Pitch.*within the BEM's discretisation error", t) for t in texts)
    assert any("negative radiation damping repaired" in t for t in texts)
    changes = ds.attrs["cleaning"]["negative_damping"]
    assert all(len(c["omega"]) <= 3 for c in changes if "interpolation" in c["method"])
    assert min(c["omega"][0] for c in changes) > 30.0  # nothing below 30 rad/s was touched
    B = ds["radiation_damping"].transpose("omega", "influenced_dof", "radiating_dof").values
    assert np.all(np.diagonal(B, axis1=1, axis2=2) >= -1e-6 * np.abs(B).max())


# ------------------------------------------------------------------ dispatch
def test_read_hydro_dispatch(tmp_path, sphere):
    other = tmp_path / "sphere_copy.dat"
    shutil.copyfile(SPHERE, other)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HydroCleaningWarning)
        by_content = read_hydro(other)
    np.testing.assert_array_equal(by_content["added_mass"].values, sphere["added_mass"].values)
    assert read_hydro(WAVESTAR, omega_range=(0, 10)).attrs["source"].startswith("BEMIO ")
    h5 = tmp_path / "wavestar.bin"
    shutil.copyfile(WAVESTAR, h5)
    assert read_hydro(h5, omega_range=(0, 10)).attrs["source"].startswith("BEMIO ")
    junk = tmp_path / "junk.xyz"
    junk.write_text("hello\n")
    with pytest.raises(HydroError, match=r"junk\.xyz: unknown hydrodynamic data format"):
        read_hydro(junk)


# ------------------------------------------------------------------ bad data
def _edit(tmp_path, old, new, count=1, name="bad.out"):
    text = SPHERE.read_text()
    assert text.count(old) >= count, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, count))
    return path


# The T = 6.283185 s block (ω = 1.0 rad/s) of sphere.out, heave row: A(3,3), B(3,3)
HEAVE_W1 = "     3     3   1.520806E+02   8.853946E+01"


def test_bad_nan_in_damping(tmp_path):
    text = SPHERE.read_text()
    assert HEAVE_W1 in text, "sphere.out changed"
    path = _edit(tmp_path, HEAVE_W1, HEAVE_W1.replace("8.853946E+01", "NaN"))
    with pytest.raises(HydroError, match=r"bad\.out: radiation_damping has NaN.*at ω = 1 rad/s \(T = 6\.2831\d s\)"
                                         r".*sphere__Heave"):
        read_wamit(path)


def _blocks(text):
    """Header and 'Wave period' blocks of a WAMIT .out text (each block starts at its title line)."""
    starts = [m.start() for m in re.finditer(r"^ Wave period", text, flags=re.M)]
    cut = [text.rfind("\n **********", 0, s) + 1 for s in starts]
    return text[:cut[0]], [text[a:b] for a, b in zip(cut, cut[1:] + [len(text)])]


def test_bad_unsorted_and_duplicate_frequencies(tmp_path, sphere):
    head, blocks = _blocks(SPHERE.read_text())
    assert len(blocks) == 242  # 240 periods + zero + infinite
    shuffled = blocks[:2] + blocks[2:][::-1]
    p = tmp_path / "unsorted.out"
    p.write_text(head + "".join(shuffled))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HydroCleaningWarning)
        ds = read_wamit(p)
    assert any("not in ascending order" in n for n in ds.attrs["notes"])
    np.testing.assert_array_equal(ds["added_mass"].values, sphere["added_mass"].values)
    dup = tmp_path / "dup.out"
    dup.write_text(head + "".join(blocks + [blocks[10]]))
    with pytest.raises(HydroError, match=r"dup\.out: duplicate frequency ω = 0\.45 rad/s"):
        read_wamit(dup)
    empty = tmp_path / "empty.out"
    empty.write_text(head + "".join(blocks[:2]))
    with pytest.raises(HydroError, match=r"empty\.out: missing frequencies"):
        read_wamit(empty)


def test_bad_asymmetric_matrix(tmp_path, sphere):
    # sphere.out itself: asymmetry 5.8e-5 (< 1e-3) -> symmetrised and recorded
    rec = sphere.attrs["cleaning"]["symmetrised"]["added_mass"]
    assert rec["max_relative_asymmetry"] == pytest.approx(5.78e-5, rel=1e-2)  # measured on the file
    # A(1,5) of the ω = 1 rad/s block changed by 10 %: scaled asymmetry ~0.1 > 1e-3
    path = _edit(tmp_path, "     1     5   3.381194E+02   5.412449E+01", "     1     5   3.719313E+02   5.412449E+01")
    with pytest.raises(HydroError, match=r"bad\.out: added_mass is not symmetric.*sphere__Surge / sphere__Pitch"
                                         r".*at ω = 1 rad/s"):
        read_wamit(path)


def test_bad_negative_damping_spike_is_interpolated_and_recorded(tmp_path, sphere):
    path = _edit(tmp_path, HEAVE_W1, HEAVE_W1.replace("8.853946E+01", "-5.000000E+01"))
    # one warning lists the spike at ω = 1 rad/s and the file's own tail (ω ≥ 11.5 rad/s, set to 0)
    with pytest.warns(HydroCleaningWarning, match=r"bad\.out: negative radiation damping repaired at 12 frequencies "
                                                  r"\(ω = 1, 11\.5\.\.12 rad/s; DOFs \['sphere__Heave'\]"):
        ds = read_wamit(path)
    first = ds.attrs["cleaning"]["negative_damping"][0]
    assert first["omega"] == [pytest.approx(1.0, rel=1e-6)] and first["dofs"] == ["sphere__Heave"]
    assert first["method"].startswith("linear interpolation")
    d = "sphere__Heave"
    B = _m(ds, "radiation_damping", d, d)
    k = int(np.argmin(np.abs(ds["omega"].values - 1.0)))
    # The repaired value is the mean of its neighbours (uniform 0.05 rad/s grid), and within 0.5 % of the
    # original 8.853946E+01 × ρω (B33 is smooth there: its curvature over ±0.05 rad/s is < 0.5 %).
    assert B[k] == pytest.approx(0.5 * (B[k - 1] + B[k + 1]), rel=1e-6)
    assert B[k] == pytest.approx(_m(sphere, "radiation_damping", d, d)[k], rel=5e-3)
    # A wide non-passive band cannot be interpolated: error, or the nearest PSD matrix if asked
    head, blocks = _blocks(SPHERE.read_text())
    for i in range(20, 30):  # 10 consecutive periods, ω = 0.95..1.4 rad/s
        m = re.search(r"^     3     3   (\S+)   (\S+)$", blocks[i], flags=re.M)
        blocks[i] = blocks[i].replace(m.group(0), f"     3     3   {m.group(1)}  -1.000000E+01")
    wide = tmp_path / "wide.out"
    wide.write_text(head + "".join(blocks))
    with pytest.raises(HydroError, match=r"wide\.out: negative radiation damping over 10 consecutive frequencies"):
        read_wamit(wide)
    with pytest.warns(HydroCleaningWarning, match="nearest positive semi-definite"):
        fixed = read_wamit(wide, negative_damping="project")
    B = _m(fixed, "radiation_damping", d, d)
    assert np.all(B >= -1e-12 * B.max())  # eigenvalue clipping leaves round-off only


def test_bad_dof_count(tmp_path):
    path = _edit(tmp_path, HEAVE_W1, HEAVE_W1 + "\n     7     7   1.000000E+00   1.000000E+00")
    with pytest.raises(HydroError, match=r"bad\.out: wrong DOF count: mode index 7.*1 bod\(y/ies\) = 6 modes"):
        read_wamit(path)
    import h5py

    h5 = tmp_path / "bad.h5"
    shutil.copyfile(WAVESTAR, h5)
    with h5py.File(h5, "r+") as f:
        a = f["body1/hydro_coeffs/added_mass/all"][()]
        del f["body1/hydro_coeffs/added_mass/all"]
        f["body1/hydro_coeffs/added_mass/all"] = a[:5, :5]
    with pytest.raises(HydroError, match=r"bad\.h5: wrong DOF count: 'body1/hydro_coeffs/added_mass/all' has shape"):
        read_bemio(h5)
    # clean() on a dataset whose radiating and influenced DOFs differ
    ds = read_bemio(WAVESTAR, omega_range=(0, 10))
    with pytest.raises(HydroError, match=r"my source: wrong DOF count: 5 radiating DOFs"):
        clean(ds.isel(radiating_dof=slice(0, 5)), source="my source")


def test_bad_nan_in_bemio(tmp_path):
    import h5py

    h5 = tmp_path / "nan.h5"
    shutil.copyfile(WAVESTAR, h5)
    with h5py.File(h5, "r+") as f:
        f["body1/hydro_coeffs/radiation_damping/all"][2, 2, 7] = np.nan  # 8th frequency, 1.6 rad/s
    with pytest.raises(HydroError, match=r"nan\.h5: radiation_damping has NaN.*ω = 1\.6 rad/s.*Float__Heave"):
        read_bemio(h5, omega_range=(0, 10))


def test_unreadable_and_missing_files(tmp_path):
    for name, reader in (("x.out", read_wamit), ("x.h5", read_bemio), ("x.nc", read_capytaine)):
        p = tmp_path / name
        p.write_bytes(b"\x00\x01garbage\xff" * 10)
        with pytest.raises(HydroError, match=re.escape(str(p))):
            reader(p)
        with pytest.raises(HydroError, match=r"missing\.\w+: no such file"):
            reader(tmp_path / f"missing{Path(name).suffix}")
    with pytest.raises(HydroError, match=r"nothing\.out: no such file"):
        read_hydro(tmp_path / "nothing.out")
    cut = tmp_path / "cut.out"
    text = SPHERE.read_text()
    cut.write_text(text[:text.index(" XBODY")])  # header only: no body data yet
    with pytest.raises(HydroError, match=r"cut\.out: no body parameters"):
        read_wamit(cut)
