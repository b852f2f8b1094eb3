"""f in compiled pieces (mbcontrol.plant.pieces; issue 38 item 3), against the expanded plant:
the one SX expression f that every other consumer (linearisation, export, the reference
integrators) uses. A long chain's steps call the pieces; here a barge chain's trajectory,
stepped by the compiled chunks in pieces, is compared with RK4 written out in numpy on the
expanded f, both fed the same excitation at the same nodes."""
import numpy as np
import pytest

import mbcontrol.plant.pieces as pieces
from mbcontrol import waves
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.sim.integrators import CALL_F_STATES, excitation_at_nodes, run_fixed_step

DT, STEPS = 0.01, 1000          # 10 s of a 1.1 s wave: ten periods from rest


@pytest.fixture
def chain(monkeypatch):
    """barge_chain N = 4 (84 states, above CALL_F_STATES) with its f in pieces, which its
    6 x 6 mass matrix would not get by itself."""
    assert build_plant(load_scene("barge_chain")).parts is None
    monkeypatch.setattr(pieces, "PIECES_MASS_NONZEROS", 36)
    plant = build_plant(load_scene("barge_chain"))
    assert plant.nx > CALL_F_STATES and plant.parts is not None
    # 8 radiation blocks (each barge's surge-pitch pair and its heave), identical ones compiled
    # once: the barges share fits
    assert len(plant.parts["radiation"]["blocks"]) == 8
    assert pieces.distinct_radiation_functions(plant) < 8
    return plant


def test_a_chain_stepped_in_pieces_follows_the_expanded_plant(chain):
    wave = waves.regular(0.03, 1.1)
    nodes = (0.0, 0.5, 1.0)
    W = excitation_at_nodes(chain, wave, STEPS, DT, nodes)
    U = np.zeros((STEPS, len(chain.inputs)))
    X, _ = run_fixed_step(chain, chain.x0(), U, W, chain.p0, DT, "rk4")
    x, f, p, u = chain.x0(), chain.f, chain.p0, U[0]
    reference = [x]
    for k in range(STEPS):       # classic RK4 on the expanded f, interpreted
        w0, w1, w2 = W[k]
        k1 = np.asarray(f(x, u, w0, p)).ravel()
        k2 = np.asarray(f(x + DT / 2 * k1, u, w1, p)).ravel()
        k3 = np.asarray(f(x + DT / 2 * k2, u, w1, p)).ravel()
        k4 = np.asarray(f(x + DT * k3, u, w2, p)).ravel()
        x = x + DT / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        reference.append(x)
    reference = np.array(reference)
    size = np.abs(reference).max(axis=0)
    assert size[chain.n_q:2 * chain.n_q].min() > 1e-4       # every velocity moved
    assert np.abs(X - reference).max(axis=0) == pytest.approx(0.0, abs=1e-9 * size.max())
    assert np.all(np.abs(X - reference).max(axis=0) <= 1e-9 * np.maximum(size, 1e-12 * size.max()))


def test_pieces_equal_f_with_parameters_in_every_piece(monkeypatch):
    """With hydro corrections (identification) the added mass, the radiation and the excitation
    depend on parameters: in M, tau and chi' alike."""
    monkeypatch.setattr(pieces, "PIECES_MASS_NONZEROS", 36)
    plant = build_plant(load_scene("barge_chain"), hydro_corrections=True)
    by_parts, rng = pieces.f_by_parts(plant), np.random.default_rng(3)
    for scale in (0.01, 0.1):
        args = [rng.normal(size=plant.f.sparsity_in(i).shape) * scale for i in range(3)]
        p = plant.p0 * rng.uniform(0.8, 1.2, plant.p0.size)
        expected = np.asarray(plant.f(*args, p)).ravel()
        got = np.asarray(by_parts(*args, p)).ravel()
        assert np.abs(got - expected).max() <= 1e-9 * np.abs(expected).max()


@pytest.fixture
def farm(monkeypatch):
    """array4 (four heaving floats, radiation coupled, 80 states) built as a farm is: its
    radiation output matrix C_r and its (constant) inverse mass matrix held as data, which
    its 4 x 72 C_r would not get by itself."""
    monkeypatch.setattr(pieces, "PIECES_RADIATION_NONZEROS", 100)
    plant = build_plant(load_scene("array4"))
    assert plant.nx > CALL_F_STATES
    assert {"inverse_mass", "outputs"} <= set(plant.parts) and "solve" not in plant.parts
    radiation = plant.parts["radiation"]
    assert radiation["output"].shape == (4, plant.nx - 2 * plant.n_q)
    # the blocks' code holds chi' only: the coupling C_r is data, not code
    assert all(block.n_out() == 1 for *_, block in radiation["blocks"])
    return plant


def test_a_farm_with_its_couplings_as_data_follows_the_expanded_plant(farm):
    """The compiled chunks (radiation force and M^-1 as dot products over arrays) against RK4
    written out in numpy on the expanded SX f (C_r chi unrolled, M \\ tau by symbolic QR),
    interpreted; and the compiled output map (C_r as data) against the expanded h."""
    from mbcontrol.sim.integrators import outputs
    wave = waves.regular(0.03, 1.1)
    W = excitation_at_nodes(farm, wave, STEPS, DT, (0.0, 0.5, 1.0))
    U = np.zeros((STEPS, len(farm.inputs)))
    X, _ = run_fixed_step(farm, farm.x0(), U, W, farm.p0, DT, "rk4")
    x, f, p, u = farm.x0(), farm.f, farm.p0, U[0]
    reference = [x]
    for k in range(STEPS):
        w0, w1, w2 = W[k]
        k1 = np.asarray(f(x, u, w0, p)).ravel()
        k2 = np.asarray(f(x + DT / 2 * k1, u, w1, p)).ravel()
        k3 = np.asarray(f(x + DT / 2 * k2, u, w1, p)).ravel()
        k4 = np.asarray(f(x + DT * k3, u, w2, p)).ravel()
        x = x + DT / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        reference.append(x)
    reference = np.array(reference)
    size = np.abs(reference).max(axis=0)
    assert size[farm.n_q:2 * farm.n_q].min() > 1e-4       # every float moved
    assert np.abs(X - reference).max() <= 1e-10 * size.max()
    assert np.all(np.abs(X - reference).max(axis=0) <= 1e-10 * np.maximum(size, 1e-6 * size.max()))
    Y = outputs(farm, X[:-1], U, W[:, 0], farm.p0)
    Y_ref = np.array([np.asarray(farm.h(X[i], U[i], W[i, 0], farm.p0)).ravel()
                      for i in range(0, STEPS, 50)])
    scale = np.abs(Y_ref).max(axis=0)
    assert scale[farm.outputs.index("radiated_power")] > 0
    assert np.all(np.abs(Y[::50] - Y_ref) <= 1e-10 * np.maximum(scale, 1e-6 * scale.max()))


def test_sparse_constant_is_sparsify_of_the_dense_matrix():
    """The farm-sized constant builder against CasADi's own: same pattern, same numbers."""
    import casadi as ca
    rng = np.random.default_rng(5)
    m = rng.normal(size=(7, 11)) * (rng.uniform(size=(7, 11)) < 0.3)
    got, expected = pieces.sparse_constant(m), ca.sparsify(ca.DM(m))
    assert got.sparsity() == expected.sparsity()
    assert np.array_equal(np.array(got.nonzeros()), np.array(expected.nonzeros()))
    assert np.array_equal(np.array(got), m)
