"""Physical checks of BEM data from every source (mbcontrol.hydro.readers.physical): a WAMIT file
whose heave added mass is negated, a damping matrix that radiates negative power, a heave
stiffness that disagrees with rho g Awp, a NaN excitation, a centre of buoyancy above the water
are refused naming the file, the entry and the frequency; the shipped data all pass, with the
margins the module documents."""
import re
import warnings

import numpy as np
import pytest

from mbcontrol.errors import HydroError
from mbcontrol.hydro import load_hydro_data, read_netcdf, write_netcdf_atomic
from mbcontrol.hydro.readers import HydroCleaningWarning, read_wamit
from mbcontrol.hydro.readers.physical import check_physical
from mbcontrol.scene import catalogue_dir, load_scene
from tests.helpers.reader_data import G, R_SPHERE, RHO, SPHERE

pytestmark = pytest.mark.skipif(not SPHERE.exists(), reason=f"reference data not found: {SPHERE}")


def _negated_heave(tmp_path, *, with_limits: bool):
    """sphere.out with A(3,3) negated in every finite-period block (and at T = 0, inf if asked):
    what a converter with a sign error would write."""
    lines, out, block = SPHERE.read_text().splitlines(), [], None
    for line in lines:
        if line.strip().startswith("Wave period"):
            block = "limit" if ("infinite" in line or "zero" in line) else "finite"
        if re.match(r"^\s+3\s+3\s+\d", line) and (block == "finite" or with_limits):
            line = re.sub(r"^(\s+3\s+3\s+)", r"\1-", line)
        out.append(line)
    path = tmp_path / "negated.out"
    path.write_text("\n".join(out) + "\n")
    return path


def _read(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HydroCleaningWarning)   # its known heave damping tail (test_readers)
        return read_wamit(path, **kw)


def test_a_negated_heave_added_mass_is_refused_at_infinite_frequency(tmp_path):
    with pytest.raises(HydroError, match=r"negated\.out: added_mass_inf\[sphere__Heave, sphere__Heave\] "
                                         r"= -1308\d\d at ω = ∞ is negative.*fix the BEM run"):
        _read(_negated_heave(tmp_path, with_limits=True))


def test_a_negated_heave_added_mass_is_refused_at_its_lowest_frequency(tmp_path):
    # A(0), A(inf) left positive: the finite-frequency curve is negative from the first period on
    # (125.66 s, i.e. 0.05 rad/s, the file's first block)
    with pytest.raises(HydroError, match=r"added_mass\[sphere__Heave, sphere__Heave\] = -21\d{4} at "
                                         r"ω = 0\.05 rad/s .*lowest frequency"):
        _read(_negated_heave(tmp_path, with_limits=False), dofs=["sphere__Heave"])


def test_a_scene_with_the_negated_file_stops_before_any_result(tmp_path):
    """The reviewer's case: a copy of the sphere scene pointing at the negated file ran and
    printed a 'valid' result a third lower; now load_hydro_data refuses it."""
    text = (catalogue_dir() / "sphere.toml").read_text()
    text = text.replace('file = "sphere_hydro.nc"\n', "").replace(
        'source = "../../shared/data/wamit/sphere.out"', f'source = "{_negated_heave(tmp_path, with_limits=True)}"')
    (tmp_path / "negsphere.toml").write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HydroCleaningWarning)
        with pytest.raises(HydroError, match=r"negated\.out.*added_mass_inf\[sphere__Heave"):
            load_hydro_data(load_scene(tmp_path / "negsphere.toml"), ["sphere__Heave"])


def test_the_sphere_passes_and_its_heave_stiffness_is_rho_g_pi_r2():
    """Independent reference: a floating hemisphere's waterplane is a disc of radius R = 5 m,
    C33 = rho g pi R^2; WAMIT's 14400-panel mesh gives 78.531 m^2 for pi 25 = 78.540 (1.1e-4)."""
    ds = _read(SPHERE)
    c33 = float(ds["hydrostatic_stiffness"].sel(radiating_dof="sphere__Heave", influenced_dof="sphere__Heave"))
    assert c33 == pytest.approx(RHO * G * np.pi * R_SPHERE ** 2, rel=2e-4)
    found = ds.attrs["cleaning"]["physical"]
    assert found["added_mass_inf_min_scaled"] >= 0 and found["resonance_bands"] == []
    assert found["damping_min_scaled_eigenvalue"] > -1e-5        # measured -7.4e-7 after the repairs


def _tampered(tmp_path, name, change):
    ds = read_netcdf(catalogue_dir() / f"{name}_hydro.nc").load()
    change(ds)
    path = tmp_path / f"{name}_tampered.nc"
    write_netcdf_atomic(ds, path)
    return path


def _scene_with_file(tmp_path, name, path):
    text = re.sub(r'^file = ".*"', f'file = "{path}"', (catalogue_dir() / f"{name}.toml").read_text(),
                  count=1, flags=re.M)
    (tmp_path / f"{name}.toml").write_text(text)
    return load_scene(tmp_path / f"{name}.toml")


def _entry(ds, var, dof):
    return ds[var].loc[dict(radiating_dof=dof, influenced_dof=dof)]


def test_a_precomputed_file_with_negated_damping_is_refused(tmp_path):
    """The package's own files pass the same gate: B33 negated -> the radiated power is negative
    (scaled eigenvalue -1, far below the -0.02 tolerance)."""
    def negate(ds):
        _entry(ds, "radiation_damping", "sphere__Heave")[:] *= -1
    scene = _scene_with_file(tmp_path, "sphere", _tampered(tmp_path, "sphere", negate))
    with pytest.raises(HydroError, match=r"sphere_tampered\.nc.*radiation_damping\[sphere__Heave, sphere__Heave\] "
                                         r"= -\S+ at ω = \S+ rad/s .*not passive"):
        load_hydro_data(scene, ["sphere__Heave"])


def test_a_heave_stiffness_against_its_waterplane_is_refused(tmp_path):
    def shrink(ds):
        ds["waterplane_area"][:] = ds["waterplane_area"].values * 0.9     # 10 % off: a wrong mesh or rho
    scene = _scene_with_file(tmp_path, "array4", _tampered(tmp_path, "array4", shrink))
    with pytest.raises(HydroError, match=r"hydrostatic_stiffness\[float1__Heave, float1__Heave\].*"
                                         r"waterplane_area\[float1\].*differ by 0\.1 > 0\.001"):
        load_hydro_data(scene, ["float1__Heave"])


@pytest.mark.parametrize("what, change, message", [
    ("negative C33", lambda ds: _entry(ds, "hydrostatic_stiffness", "sphere__Heave").__imul__(-1),
     r"hydrostatic_stiffness\[sphere__Heave, sphere__Heave\] = -7703\d\d N/m is negative"),
    ("NaN excitation", lambda ds: ds["excitation_force"].__setitem__(
        (Ellipsis,), np.where(np.arange(ds.sizes["omega"])[None, :, None] == 7, np.nan,
                              ds["excitation_force"].values)),
     r"excitation_force has NaN or infinite values at ω = "),
    ("buoyancy above the water", lambda ds: ds["center_of_buoyancy"].loc[dict(xyz="z")].__imul__(-1),
     r"center_of_buoyancy\[sphere\] is 1\.87\d* m above the free surface"),
], ids=["C33 < 0", "NaN excitation", "CoB above water"])
def test_impossible_hydrostatics_and_excitation_are_refused(tmp_path, what, change, message):
    def apply(ds):
        change(ds)
    path = _tampered(tmp_path, "sphere", apply)
    with pytest.raises(HydroError, match=message):
        check_physical(read_netcdf(path), str(path))


SHIPPED = sorted(p.name for p in catalogue_dir().glob("*_hydro.nc"))
# rm3_moored: the float's surge A(inf) is 1.02 % of the largest translational one, the heave
# plate's heave: a surface float beside a 30 m plate (measured 0.0102; physical, not an error)
SMALL_ADDED_MASS = {"rm3_moored_hydro.nc": 0.010}


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_file_passes_with_the_documented_margins(name):
    """Margins measured when the tolerances were chosen (module physical): damping eigenvalue
    >= -0.0119 (raft3) against the -0.02 gate, A(inf) diagonal >= 0.066 of its scale."""
    found = check_physical(read_netcdf(catalogue_dir() / name), name)
    assert found["damping_min_scaled_eigenvalue"] >= -0.0119 - 1e-4
    assert found.get("added_mass_inf_min_scaled", 1.0) >= SMALL_ADDED_MASS.get(name, 0.066)
    assert found["c33_vs_rho_g_awp"] < 1e-12


def test_a_gap_resonance_is_accepted_and_reported():
    """hinged_barge's two barges have a narrow gap: their surge added mass dips below zero
    between 10.7 and 15 rad/s (values in the file) and is positive on both sides: physical
    (a resonance), reported, not refused."""
    found = check_physical(read_netcdf(catalogue_dir() / "hinged_barge_hydro.nc"), "hinged_barge")
    bands = {b["entry"]: b for b in found["resonance_bands"]}
    assert set(bands) == {"added_mass[barge1__Surge, barge1__Surge]", "added_mass[barge2__Surge, barge2__Surge]"}
    assert bands["added_mass[barge1__Surge, barge1__Surge]"]["omega"] == pytest.approx([10.7, 15.0])
