"""Identical bodies without hydrodynamic interaction are fitted once (issue 38 item 3), and a
block-diagonal model's passivity is tested group by group: against the data each copy must
fit (its own kernel, recomputed here), the exact passivity test of the whole model, and a
farm-sized chain's choice of fit.

barge_chain's data (4 identical barges, each solved alone) has 8 decoupled DOF groups: each
barge's surge-pitch pair and its heave."""
import numpy as np
import pytest
import xarray as xr

from mbcontrol.hydro import fit_method, kernel_data
from mbcontrol.hydro.data.netcdf import read_netcdf
from mbcontrol.hydro.fit.passivity import passivity_test, passivity_test_groups
from mbcontrol.hydro.fit.radiation import coupled_groups, fit_radiation
from mbcontrol.scene import catalogue_dir

OMEGA_MAX = 16.0     # rad/s: the 40 mm panels resolve the barges below 16.8 rad/s


@pytest.fixture(scope="module")
def data():
    return read_netcdf(catalogue_dir() / "barge_chain_N4_hydro.nc")


@pytest.fixture(scope="module")
def fit(data):
    return fit_radiation(data, tol=0.02, omega_max=OMEGA_MAX)


def test_the_barges_radiate_in_eight_decoupled_groups(data):
    groups = coupled_groups(data, list(data["radiating_dof"].values))
    assert sorted(map(tuple, groups)) == sorted(
        [(f"barge{i}__Surge", f"barge{i}__Pitch") for i in range(1, 5)]
        + [(f"barge{i}__Heave",) for i in range(1, 5)])


def test_one_barge_is_fitted_and_the_others_reuse_it_within_tolerance_of_their_own_data(data, fit):
    groups = fit.report["groups"]
    assert [g.get("reused", False) for g in groups].count(False) == 2     # one barge's two groups
    w, K, dofs = kernel_data(data, omega_max=OMEGA_MAX)
    response = fit.frequency_response(w)
    blocks = {}
    for group in groups:
        idx = [dofs.index(d) for d in group["dofs"]]
        # the reused fit is judged on this barge's own data, recomputed here: relative RMS error
        err = np.linalg.norm(response[:, idx][:, :, idx] - K[:, idx][:, :, idx]) / np.linalg.norm(
            K[:, idx][:, :, idx])
        assert err <= 0.02, (group["dofs"], err)
        states = np.flatnonzero(np.any(fit.B[:, idx] != 0, axis=1))
        blocks.setdefault(len(idx), []).append(fit.A[np.ix_(states, states)])
    for copies in blocks.values():        # every barge's block is the first one's
        assert all(np.array_equal(a, copies[0]) for a in copies)


def test_passivity_group_by_group_is_the_whole_models(fit):
    groups = fit.report["groups"]
    dofs = list(fit.dofs)
    parts = []
    for group in groups:
        idx = [dofs.index(d) for d in group["dofs"]]
        states = np.flatnonzero(np.any(fit.B[:, idx] != 0, axis=1))
        parts.append((idx, fit.A[np.ix_(states, states)], fit.B[np.ix_(states, idx)],
                      fit.C[np.ix_(idx, states)]))
    grouped, whole = passivity_test_groups(parts), passivity_test(fit.A, fit.B, fit.C)
    assert grouped.passive == whole.passive
    # extremes over each test's own grid (a group's spans its own poles): equal to the grids'
    # resolution of a smooth maximum (measured 8e-6), the least one refined by both searches
    assert grouped.max_eig == pytest.approx(whole.max_eig, rel=1e-4)
    assert grouped.min_eig == pytest.approx(whole.min_eig, rel=1e-4, abs=1e-9 * whole.max_eig)
    assert "2 distinct of 8" in grouped.method


def _chain_of(data, n):
    """Block-diagonal data of n copies of barge 1 (no interaction): a farm-sized chain."""
    one = data.sel(radiating_dof=data["radiating_dof"].values[:3],
                   influenced_dof=data["influenced_dof"].values[:3])
    names = [f"b{k}__{d.split('__')[1]}" for k in range(n) for d in one["radiating_dof"].values]
    out = {}
    for var in ("added_mass", "radiation_damping"):
        out[var] = (("omega", "radiating_dof", "influenced_dof"),
                    np.stack([np.kron(np.eye(n), m) for m in one[var].values]))
    out["added_mass_inf"] = (("radiating_dof", "influenced_dof"),
                             np.kron(np.eye(n), one["added_mass_inf"].values))
    return xr.Dataset(out, coords={"omega": one["omega"].values, "radiating_dof": names,
                                   "influenced_dof": names}), names


def test_a_chain_of_nine_independent_barges_is_not_an_array(data):
    chain, dofs = _chain_of(data, 9)
    assert fit_method("auto", dofs) == "columns"            # nine bodies, coupling unknown
    assert fit_method("auto", dofs, chain) == "coupled"     # nine bodies, none coupled
    coupled = chain.copy(deep=True)
    coupled["radiation_damping"][:] += 1e-2 * coupled["radiation_damping"].values.max()
    assert fit_method("auto", dofs, coupled) == "columns"   # every body coupled to every other
