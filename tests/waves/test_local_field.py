"""The incident field about a body as Chebyshev series (mbcontrol.waves.local_field): each
number against an independent reference: the exact sums over components, closed forms of one
component, numerical Chebyshev interpolation, and numpy for the CasADi evaluation."""
import math

import casadi as ca
import numpy as np
import pytest
from numpy.polynomial import chebyshev as C

from mbcontrol.errors import WaveError
from mbcontrol.waves import Spreading, irregular, regular, wavenumber
from mbcontrol.waves import (LocalField, band_field, choose_field, direct_elevation,
                             direct_pressure, field_rows_offsets, field_rows_series)

RHO, G = 1025.0, 9.81
X0, Y0 = 3.0, -2.0             # the reference point: off the origin, so its phase matters
TOL = 1e-3                     # m of head


def _points(field, n, rng, water_depth, eta_of):
    """n random points inside the field's box: xi in [-L, L], any cross-wave offset, and a
    stretched depth in [0, D] (z from d by inverting the stretching at the exact eta)."""
    xi, across = rng.uniform(-1, 1, n) * field.half_width, rng.uniform(-30, 30, n)
    c, s = math.cos(field.direction), math.sin(field.direction)
    x, y = field.x0 + xi * c - across * s, field.y0 + xi * s + across * c
    d, eta = rng.uniform(0, field.depth_range, n), eta_of(x, y)
    z = d - eta if math.isinf(water_depth) else d * (water_depth + eta) / water_depth - eta
    return x, y, z


WAVES = {"regular": lambda: regular(2.0, 6.0, phase=0.4, direction=-1.1),
         "jonswap": lambda: irregular(2.5, 9.0, direction=0.6, duration=300.0)}


@pytest.mark.parametrize("water_depth", [math.inf, 30.0])
@pytest.mark.parametrize("kind", sorted(WAVES))
def test_series_equal_the_direct_sums_inside_the_box(kind, water_depth):
    wave = WAVES[kind]()
    field = choose_field(wave, X0, Y0, 10.0, 12.0, water_depth=water_depth, tol=TOL)
    # the bound that chose the orders: below tol, and so must every error be (stated: 1e-3 m)
    assert np.sum(wave.amplitude * field.truncation_error(wave.omega)) <= TOL
    rng = np.random.default_rng(7)
    for t in (1.3, 37.3, 211.9):           # inside the ramp and after it
        rows = field_rows_series(field, wave, [t])[0]
        x, y, z = _points(field, 300, rng, water_depth,
                          lambda x, y: direct_elevation(wave, t, x, y, water_depth=water_depth))
        eta = direct_elevation(wave, t, x, y, water_depth=water_depth)
        assert np.max(np.abs(field.elevation(rows, x, y) - eta)) <= TOL
        p = direct_pressure(wave, t, x, y, z, water_depth=water_depth, rho=RHO, g=G)
        assert np.max(np.abs(field.pressure(rows, x, y, z, RHO, G) - p)) / (RHO * G) <= TOL
        assert not field.outside(rows, x, y, z).any()


def test_a_tight_tolerance_is_met_too():
    """The bound is a bound at 1e-8 m as well (orders chosen to it, errors below it)."""
    wave = regular(1.0, 7.0, phase=1.0, direction=0.3)
    field = choose_field(wave, X0, Y0, 8.0, 10.0, tol=1e-8)
    rng = np.random.default_rng(3)
    rows = field_rows_series(field, wave, [50.0])[0]
    x, y, z = _points(field, 200, rng, math.inf, lambda x, y: direct_elevation(wave, 50.0, x, y))
    assert np.max(np.abs(field.elevation(rows, x, y) - direct_elevation(wave, 50.0, x, y))) <= 1e-8
    p = direct_pressure(wave, 50.0, x, y, z, rho=RHO, g=G)
    assert np.max(np.abs(field.pressure(rows, x, y, z, RHO, G) - p)) / (RHO * G) <= 1e-8


@pytest.mark.parametrize("water_depth", [math.inf, 30.0])
def test_pressure_vanishes_on_and_above_the_incident_surface(water_depth):
    wave = irregular(2.5, 9.0, direction=0.6, duration=300.0)
    field = choose_field(wave, X0, Y0, 10.0, 12.0, water_depth=water_depth, tol=TOL)
    rng = np.random.default_rng(11)
    t = 77.7
    rows = field_rows_series(field, wave, [t])[0]
    x, y, _ = _points(field, 300, rng, water_depth, lambda x, y: 0 * x)
    eta = direct_elevation(wave, t, x, y, water_depth=water_depth)
    on = field.pressure(rows, x, y, -eta, RHO, G)
    assert np.max(np.abs(on)) / (RHO * G) <= TOL                       # the series' tolerance
    # the direct sum: zero but for the rounding of two orders of summation (1e-12 Pa)
    assert np.max(direct_pressure(wave, t, x, y, -eta, water_depth=water_depth)) < 1e-9
    above = -eta - rng.uniform(2 * TOL, 2.0, eta.size)
    assert np.all(field.pressure(rows, x, y, above, RHO, G) == 0)      # exactly: fmax
    assert np.all(direct_pressure(wave, t, x, y, above, water_depth=water_depth) == 0)


@pytest.mark.parametrize("water_depth", [math.inf, 30.0])
def test_one_component_at_the_reference_point_is_the_closed_form(water_depth):
    """eta = a cos(k xi0 - omega t - phi) and p = rho g (z + eta Z(d)), d the stretched depth,
    Z = exp(-k d) or cosh(k (H - d)) / cosh(k H): written out here, not from the module."""
    height, period, phase, beta = 1.6, 7.0, 0.9, 0.4
    wave = regular(height, period, phase=phase, direction=beta)
    field = choose_field(wave, X0, Y0, 10.0, 12.0, water_depth=water_depth, tol=1e-6)
    omega = 2 * math.pi / period
    k = wavenumber(omega, water_depth)
    t = 40.0                                                     # past the ramp (2 T)
    eta = height / 2 * math.cos(k * (X0 * math.cos(beta) + Y0 * math.sin(beta)) - omega * t - phase)
    rows = field_rows_series(field, wave, [t])[0]
    for z in (-0.5 * eta, 0.0, 3.0, 9.0):
        d = z + eta if math.isinf(water_depth) else water_depth * (z + eta) / (water_depth + eta)
        Z = math.exp(-k * d) if math.isinf(water_depth) else \
            math.cosh(k * (water_depth - d)) / math.cosh(k * water_depth)
        p = RHO * G * (z + eta * Z)
        assert direct_pressure(wave, t, X0, Y0, z, water_depth=water_depth, rho=RHO, g=G) \
            == pytest.approx(p, rel=1e-12, abs=1e-9)
        assert field.pressure(rows, X0, Y0, z, RHO, G) == pytest.approx(p, abs=1e-6 * RHO * G)
    assert field.elevation(rows, X0, Y0) == pytest.approx(eta, abs=1e-6)
    assert direct_elevation(wave, t, X0, Y0, water_depth=water_depth) \
        == pytest.approx(eta, abs=1e-12)


@pytest.mark.parametrize("omega, water_depth", [(0.5, math.inf), (1.3, math.inf), (2.4, math.inf),
                                                (0.5, 30.0), (1.0, 15.0), (2.0, 20.0)])
def test_closed_form_coefficients_equal_numerical_interpolation(omega, water_depth):
    """Jacobi-Anger (J_m) and the I_n forms against interpolation at 61 Chebyshev points,
    and the rows are their products, m-major."""
    field = LocalField(X0, Y0, 0.7, 9.0, 14.0, 10, 7, water_depth)
    k = wavenumber(omega, water_depth)
    xi0 = X0 * math.cos(0.7) + Y0 * math.sin(0.7)
    along = lambda u: np.exp(1j * k * (xi0 + field.half_width * u))          # noqa: E731
    a = (C.chebinterpolate(lambda u: along(u).real, 60)
         + 1j * C.chebinterpolate(lambda u: along(u).imag, 60))[:field.n_xi]
    d = lambda v: field.depth_range * (v + 1) / 2                            # noqa: E731
    Z = (lambda v: np.exp(-k * d(v))) if math.isinf(water_depth) else \
        (lambda v: np.cosh(k * (water_depth - d(v))) / np.cosh(k * water_depth))
    b = C.chebinterpolate(Z, 60)[:field.n_depth]
    rows = field.row_coefficients([omega])[0]
    np.testing.assert_allclose(rows[:field.n_xi], a, rtol=0, atol=1e-13)
    np.testing.assert_allclose(rows[field.n_xi:], np.outer(a, b).ravel(), rtol=0, atol=1e-13)


@pytest.mark.parametrize("water_depth", [math.inf, 25.0])
def test_truncation_error_bounds_the_error_over_the_box(water_depth):
    """A low-order field of one component against the exact complex field on a 61 x 61 grid:
    the error (any phase: complex modulus) stays under the bound and is not far below it."""
    omega = 1.6
    field = LocalField(X0, Y0, 0.2, 8.0, 10.0, 7, 4, water_depth)
    k = wavenumber(omega, water_depth)
    rows = field.row_coefficients([omega])[0]
    u = np.cos(np.linspace(0, np.pi, 61))             # Chebyshev-dense near the edges
    uu, vv = np.meshgrid(u, u, indexing="ij")
    xi0 = X0 * math.cos(0.2) + Y0 * math.sin(0.2)
    d = field.depth_range * (vv + 1) / 2
    Z = np.exp(-k * d) if math.isinf(water_depth) else \
        np.cosh(k * (water_depth - d)) / np.cosh(k * water_depth)
    exact = np.exp(1j * k * (xi0 + field.half_width * uu)) * Z
    series = C.chebval2d(uu, vv, rows[field.n_xi:].reshape(field.n_xi, field.n_depth))
    bound = field.truncation_error([omega])[0]
    error = np.max(np.abs(series - exact))
    eta_error = np.max(np.abs(C.chebval(u, rows[:field.n_xi]) - exact[:, 0] / Z[:, 0]))
    assert eta_error <= error <= bound < 10 * error


def test_casadi_evaluation_equals_numpy():
    field = LocalField(X0, Y0, 0.6, 10.0, 12.0, 9, 6, 30.0)
    rng = np.random.default_rng(5)
    values = rng.normal(size=field.n_rows) * 0.3
    # inside and outside the box, above and below the surface (clamps and fmax exercised)
    x, y, z = rng.uniform(-20, 25, 80), rng.uniform(-20, 20, 80), rng.uniform(-3, 20, 80)
    rows, X, Y, Z = (ca.SX.sym("rows", field.n_rows), ca.SX.sym("x", 1, 80),
                     ca.SX.sym("y", 1, 80), ca.SX.sym("z", 1, 80))
    fun = ca.Function("f", [rows, X, Y, Z], [field.elevation(rows, X, Y),
                                              field.pressure(rows, X, Y, Z, RHO, G)])
    eta, p = (np.asarray(v).ravel() for v in fun(values, x[None], y[None], z[None]))
    np.testing.assert_allclose(eta, field.elevation(values, x, y), rtol=0, atol=1e-12)
    np.testing.assert_allclose(p / (RHO * G), field.pressure(values, x, y, z, RHO, G) / (RHO * G),
                               rtol=0, atol=1e-12)
    usage = ca.Function("u", [rows, X, Y, Z], [field.usage(rows, X, Y, Z)])
    used = np.asarray(usage(values, x[None], y[None], z[None])).ravel()
    outside = field.outside(values, x, y, z)
    assert outside.any() and not outside.all()
    np.testing.assert_array_equal(used > 1.0, outside)
    # the box's own edges by hand: |xi| / L and the Wheeler-stretched depth over D
    xi = (x - field.x0) * math.cos(field.direction) + (y - field.y0) * math.sin(field.direction)
    eta, H = field.elevation(values, x, y), field.water_depth
    np.testing.assert_allclose(used, np.maximum(np.abs(xi) / field.half_width,
                                                H * (z + eta) / (H + eta) / field.depth_range),
                               rtol=1e-12)


def test_orders_grow_with_the_box_and_the_frequency():
    wave = regular(1.0, 8.0)
    m = [choose_field(wave, 0, 0, L, 8.0).n_xi for L in (2.0, 8.0, 20.0, 40.0)]
    assert m == sorted(m) and m[0] < m[-1]
    fields = [choose_field(regular(0.5, T), 0, 0, 8.0, 8.0) for T in (14.0, 8.0, 5.0, 3.0)]
    m, n = [f.n_xi for f in fields], [f.n_depth for f in fields]
    assert m == sorted(m) and m[0] < m[-1] and n == sorted(n) and n[0] < n[-1]


def test_what_choose_field_refuses_or_warns_about():
    spread = irregular(2.0, 8.0, duration=200.0, spreading=Spreading("cos2s", 0.0, 0.4))
    with pytest.raises(WaveError, match="long-crested"):
        choose_field(spread, 0, 0, 10.0, 10.0)
    wave = regular(1.0, 5.0)
    with pytest.raises(WaveError, match="max_order|orders 3 x 3"):
        choose_field(wave, 0, 0, 30.0, 10.0, max_order=3)
    reached = float(np.sum(wave.amplitude * LocalField(0, 0, 0.0, 10.0, 10.0, 6, 6)
                           .truncation_error(wave.omega)))
    with pytest.warns(RuntimeWarning, match="orders 6 x 6"):
        field = choose_field(wave, 0, 0, 10.0, 10.0, max_order=6, tol=reached / 2)
    assert (field.n_xi, field.n_depth) == (6, 6)
    with pytest.raises(WaveError, match="direction"):
        field_rows_series(field, regular(1.0, 5.0, direction=0.5), [0.0])
    with pytest.raises(WaveError, match="water depth"):
        LocalField(0, 0, 0.0, 10.0, 40.0, 4, 4, water_depth=30.0)


def test_rows_at_stage_offsets_equal_rows_at_those_times():
    wave = irregular(2.5, 9.0, direction=0.6, duration=300.0)
    field = LocalField(X0, Y0, 0.6, 10.0, 12.0, 6, 4)
    stages = field_rows_offsets(field, wave, 400, 0.1, (0.0, 0.5, 1.0))
    t = (np.arange(400)[:, None] + np.array([0.0, 0.5, 1.0])) * 0.1
    np.testing.assert_allclose(stages, field_rows_series(field, wave, t.ravel()).reshape(
        stages.shape), rtol=0, atol=1e-10)
