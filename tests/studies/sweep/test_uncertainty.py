"""The annual energy's budget (studies.sweep.budget, .uncertainty): its sums against hand
calculations, and the parameter and model components of an identification against sweeps
run at the parameter's ends (brute force: simulated, not linear theory)."""
import json
import math

import numpy as np
import pytest
from scipy.stats import t as student

from mbcontrol.studies.sweep import budget, sweep
from mbcontrol.waves import read_seas
from mbcontrol.studies.sweep.uncertainty import read_identified

H = 8766 / 1e6          # MWh per W over a year
SHORT = dict(duration=150.0, dt=0.1, progress=False, workers=0)   # 2 Tp + 10 Tp of 12 s


def test_budget_sums_by_hand():
    w = np.array([0.5, 0.3, 0.2])
    stat = budget.statistical(w, [100.0, 200.0, math.nan], [3, 3, math.inf])
    assert stat["std_MWh"] == pytest.approx(H * math.hypot(0.5 * 100, 0.3 * 200))
    assert stat["seas_without_estimate"] == 1
    # Welch-Satterthwaite within the component: u^4 / sum(u_i^4 / nu_i)
    assert stat["dof"] == pytest.approx(
        stat["std_MWh"] ** 4 / ((H * 50) ** 4 / 3 + (H * 60) ** 4 / 3))
    model = budget.linear_over_seas("model", w, [-10.0, 20.0, 30.0], "hand")
    assert model["std_MWh"] == pytest.approx(H * (-5 + 6 + 6)) and model["signed_MWh"] > 0
    cov = np.array([[4.0, 1.0], [1.0, 9.0]])
    grads = np.array([[1.0, 2.0], [3.0, 0.0], [0.0, 1.0]])
    par = budget.parameters(w, grads, cov, ["a", "b"], "hand")
    G = H * np.array([0.5 + 0.9, 1.0 + 0.2])
    assert par["std_MWh"] == pytest.approx(math.sqrt(G @ cov @ G))
    years = {"2001": [0.6, 0.3, 0.1], "2002": [0.4, 0.3, 0.3], "2003": [0.5, 0.4, 0.1]}
    power = np.array([1e5, 2e5, 3e5])
    res = budget.resource(years, power)
    aeps = [H * np.dot(v, power) for v in years.values()]
    assert res["interannual_std_MWh"] == pytest.approx(np.std(aeps, ddof=1))
    assert res["std_MWh"] == pytest.approx(np.std(aeps, ddof=1) / math.sqrt(3))
    gone = budget.absent("radiation_fit", "B", "linear", "not linear")
    ci, table = budget.combine(100.0, [stat, model, par, res, gone])
    u = math.sqrt(sum(c["std_MWh"] ** 2 for c in (stat, model, par, res)))
    dof = u ** 4 / (stat["std_MWh"] ** 4 / stat["dof"] + res["std_MWh"] ** 4 / 2)
    k = student.ppf(0.975, dof)
    assert table["combined_std_MWh"] == pytest.approx(u)
    assert table["coverage_factor"] == pytest.approx(k)
    assert ci == pytest.approx([100 - k * u, 100 + k * u])
    assert sum(c["share_of_variance"] for c in table["components"]
               if c["share_of_variance"] is not None) == pytest.approx(1.0)
    assert table["components"][-1]["std_MWh"] is None and "not linear" in budget.table(table)


def _identification(tmp_path, model="sphere", value=4e5, std=4e4):
    path = tmp_path / "summary.json"
    path.write_text(json.dumps({
        "model": model, "parameters": {"pto__damping": {"value": value, "std": std}},
        "correlation": [[1.0]], "fit": {"rms_error": 0.05},
        "validation": {"rms_error": 0.08}}))
    return path


def test_identification_propagates_to_the_annual_energy(tmp_path):
    """The scene's own damper identified as 400 +- 40 kN s/m: the sweep runs the identified
    value; its parameter component matches the annual energies simulated at 400 -+ 40 kN s/m
    (central difference of two more sweeps); the model component is 2 x 8 % of the annual
    energy (power ~ amplitude^2); the resource term is the spread over the file's years."""
    seas_file = tmp_path / "seas.csv"
    seas_file.write_text("Hm0,Tp,weights,weights_2001,weights_2002,weights_2003\n"
                         "1.0,8,0.5,0.6,0.4,0.5\n2.0,10,0.3,0.3,0.3,0.4\n"
                         "3.0,12,0.2,0.1,0.3,0.1\n")
    seas = read_seas(seas_file)
    from mbcontrol.waves import read_year_weights
    years = read_year_weights(seas_file)
    ident = _identification(tmp_path)
    _, result = sweep("sphere", seas, identified=ident, years=years, **SHORT)
    assert result["provenance"]["identified"] == str(ident)
    ends = [sweep("sphere", seas, params={"pto__damping": c}, **SHORT)[1]["annual_energy_MWh"]
            for c in (3.6e5, 4.4e5)]
    components = {c["component"]: c for c in result["annual_energy_budget"]["components"]}
    brute = abs(ends[1] - ends[0]) / 2           # sigma x dAEP/dc, simulated
    assert components["parameters"]["std_MWh"] == pytest.approx(brute, rel=0.1)
    aep = result["annual_energy_MWh"]
    for row in result["seas"]:                      # per sea: the same parts, in W
        assert row["model_std_W"] == pytest.approx(0.16 * row["mean_power_W"])
        assert 0 < row["parameter_std_W"] < row["mean_power_W"]
    assert components["model"]["std_MWh"] == pytest.approx(2 * 0.08 * aep)
    assert "validation" in components["model"]["source"]
    powers = np.array([r["mean_power_W"] for r in result["seas"]])
    by_year = [H * np.dot(w, powers) for w in years.values()]
    assert components["resource"]["std_MWh"] == pytest.approx(np.std(by_year, ddof=1) / math.sqrt(3))
    # one seed of a linear law: the statistical part is the spectral estimate
    assert components["statistical"]["std_MWh"] == pytest.approx(H * math.sqrt(sum(
        (r["weight"] * r["spectral_stderr_W"]) ** 2 for r in result["seas"])))
    assert components["radiation_fit"]["std_MWh"] is not None
    u = result["annual_energy_budget"]["combined_std_MWh"]
    lo, hi = result["annual_energy_ci95_MWh"]
    k = result["annual_energy_budget"]["coverage_factor"]       # 3 years: few dof, k > 1.96
    assert k > 1.96 and (hi - lo) / 2 == pytest.approx(k * u) and lo < aep < hi


def test_identification_of_another_model_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"summary.json: field 'model' is 'rm3'"):
        read_identified(_identification(tmp_path, model="rm3"), "sphere", ["pto__damping"])
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"model": "sphere", "parameters": {}, "fit": {}}))
    with pytest.raises(ValueError, match=r"bad.json: field 'correlation' missing"):
        read_identified(path, "sphere", ["pto__damping"])


def test_the_calibrated_model_error_is_preferred(tmp_path):
    """An identification with a CV+ calibration: its 95 % quantile of relative held-out
    errors / 1.96 is the model's 1-sigma error, before the validation RMS."""
    path = _identification(tmp_path)
    summary = json.loads(path.read_text())
    summary["calibration"] = {"quantile": 0.196, "alpha": 0.05, "method": "CV+"}
    path.write_text(json.dumps(summary))
    got = read_identified(path, "sphere", ["pto__damping"])
    assert got["model_error"] == pytest.approx(0.196 / 1.959964)
    assert "calibrated" in got["model_error_source"]


def test_a_nonlinear_law_says_what_it_lacks(tmp_path):
    """Latching with two seeds: no spectral estimate, no radiation-fit term; each listed as
    absent with its reason, and the interval carries what is known."""
    seas_file = tmp_path / "seas.csv"
    seas_file.write_text("Hm0,Tp,weights\n1.0,8,0.6\n2.0,10,0.4\n")
    _, result = sweep("sphere", read_seas(seas_file), controller="latching", seeds=2,
                      settings={"damping": 4e5, "latch_time": 1.0}, **SHORT)
    rows = {c["component"]: c for c in result["annual_energy_budget"]["components"]}
    # two seas of two seeds, one degree of freedom each: Welch-Satterthwaite gives 1 to 2
    assert rows["statistical"]["std_MWh"] > 0 and 1 <= rows["statistical"]["dof"] <= 2
    assert "not linear" in rows["radiation_fit"]["absent"]
    assert "spectral_cv" not in result["seas"][0]
