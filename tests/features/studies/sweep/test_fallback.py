"""A per-sea design sweep records every sea (issue 58, item 6): a storm sea whose tuned law
fails falls back (fell_back in the store and the summary) and its energy counts; a sea no law
within the PTO's limits serves is recorded as zero with its reason (zero_seas, the notes)."""
import numpy as np
import pytest

from mbcontrol.scene import catalogue_dir
from mbcontrol.studies.sweep import annual_energy_MWh, read_seas, sweep

SEAS = "Hm0,Tp,weights\n2.0,9.0,0.9\n6.13,11.86,0.1\n"


@pytest.fixture
def site(tmp_path):
    path = tmp_path / "site.csv"
    path.write_text(SEAS)
    return read_seas(path)


def _sphere_with(tmp_path, force_max: float) -> str:
    """The catalogue sphere with another force_max (N), as a scene file in tmp_path."""
    text = (catalogue_dir() / "sphere.toml").read_text()
    text = text.replace('file = "sphere_hydro.nc"', f'file = "{catalogue_dir() / "sphere_hydro.nc"}"')
    assert "force_max = 2.0e6" in text
    path = tmp_path / "sphere_weak.toml"
    path.write_text(text.replace("force_max = 2.0e6", f"force_max = {force_max!r}"))
    return str(path)


def test_storm_sea_falls_back_and_counts(site):
    """The catalogue sphere, passive: the storm sea (Hs 6.13 m) fell back to the saturated
    damper, ran valid, and its power enters the annual energy (the energy of both seas by
    waves.annual_energy_MWh from the per-sea powers)."""
    ds, summary = sweep("sphere", site, controller="passive", design=True, duration=200.0,
                        workers=0, progress=False)
    assert ds["fell_back"].values[:, 0].tolist() == [False, True]
    assert not ds["no_law"].values.any()
    assert summary["fell_back_seas"] == 1 and summary["fell_back"][0]["hs"] == 6.13
    assert summary["fell_back"][0]["to"] == "passive, saturated at force_max"
    rows = summary["seas"]
    assert [r["fell_back"] for r in rows] == [False, True]
    assert summary["valid_cases"] == 2 and summary["zero_seas"] == []
    power = [r["mean_power_W"] for r in rows]
    assert all(np.isfinite(power)) and power[1] > 0
    assert summary["annual_energy_MWh"] == pytest.approx(
        annual_energy_MWh(np.array(power), np.array([0.9, 0.1])), rel=1e-12)
    assert any("fell back" in n for n in summary["notes"])


def test_sea_no_law_serves_is_zero_with_its_reason(site, tmp_path):
    """force_max 0.5 MN: the storm sea has no law (the stroke passes 4 m whatever force within
    0.5 MN): not run, no_law in the store, counted as zero in the annual energy with its reason
    in zero_seas and the notes; the moderate sea runs as tuned."""
    ds, summary = sweep(_sphere_with(tmp_path, 5e5), site, controller="reactive", design=True,
                        duration=200.0, workers=0, progress=False)
    assert ds["no_law"].values[:, 0].tolist() == [False, True]
    # it fell back to nothing: not among the seas whose fallback law ran and counts
    assert ds["fell_back"].values[:, 0].tolist() == [False, False]
    assert summary["fell_back_seas"] == 0
    assert summary["failed_cases"] == 0 and summary["invalid_cases"] == 1
    (zero,) = summary["zero_seas"]
    assert zero["hs"] == 6.13 and zero["kind"] == "no_law"
    assert "survival" in zero["why"] and "stroke_max 4 m" in zero["why"]
    power = summary["seas"][0]["mean_power_W"]
    assert summary["annual_energy_MWh"] == pytest.approx(
        annual_energy_MWh(np.array([power, 0.0]), np.array([0.9, 0.1])), rel=1e-12)
    assert any("1 with no law within the PTO's limits (survival)" in n
               for n in summary["notes"])
