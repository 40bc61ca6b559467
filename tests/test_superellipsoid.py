"""The superellipsoid: analytic forms, the B-spline fit within its stated tolerance,
the ellipsoid case and the sharp / pinched extremes."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.construct.superellipsoid import superellipsoid_implicit, superellipsoid_points


def _random_uv(n=3000, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 1, n), rng.uniform(0, 1, n)


@pytest.mark.parametrize("s1, s2", [(1, 1), (0.5, 0.5), (0.1, 0.1), (0.1, 1.0), (3, 3), (2.5, 0.3)])
def test_fit_within_tolerance_of_the_analytic_surface(s1, s2):
    s = sm.superellipsoid(2.0, 1.5, 1.0, s1, s2)
    assert s.tolerance == pytest.approx(2e-3)
    assert s.max_deviation <= s.tolerance
    u, v = _random_uv()
    dev = np.linalg.norm(s.points(u, v) - s.analytic_points(u, v), axis=-1).max()
    assert dev <= s.tolerance  # independent random samples, not the fit's own check grid
    # the analytic points satisfy the implicit form
    assert np.abs(s.implicit(s.analytic_points(u, v))).max() < 1e-12


def test_ellipsoid_case_is_the_ellipsoid():
    rx, ry, rz = 3.0, 2.0, 1.0
    eta = np.linspace(-np.pi / 2, np.pi / 2, 37)[:, None]
    om = np.linspace(-np.pi, np.pi, 73)[None, :]
    p = superellipsoid_points(rx, ry, rz, 1, 1, eta, om)
    ref = np.stack(np.broadcast_arrays(rx * np.cos(eta) * np.cos(om), ry * np.cos(eta) * np.sin(om), rz * np.sin(eta)), -1)
    assert np.abs(p - ref).max() < 1e-15
    s = sm.superellipsoid(rx, ry, rz, 1, 1, tolerance=1e-5)
    u, v = _random_uv(2000, 1)
    q = s.points(u, v)
    # geometric distance to the ellipsoid, first order F/|grad F|
    F = sm.to_implicit(s)
    assert np.abs(F.distance_estimate(q)).max() <= 1e-5
    assert np.abs((q[:, 0] / rx) ** 2 + (q[:, 1] / ry) ** 2 + (q[:, 2] / rz) ** 2 - 1).max() < 3e-5


def test_spline_is_its_occt_twin():
    s = sm.superellipsoid(2.0, 1.5, 1.0, 1.0, 1.0)
    assert s.exact_in_occt
    r = sm.crosscheck(s, samples=10)
    assert r.mode == "parametric" and r.passed
    # pinched: positions and derivatives agree with OCCT's D2 to round-off (normals and
    # curvature at the parametric cusps are limits and are not compared here)
    r = sm.crosscheck(sm.superellipsoid(1.0, 1.0, 1.0, 0.5, 2.0), samples=10)
    assert r.details["position_rel"] < 1e-14 and r.details["d1_rel"] < 1e-12 and r.details["d2_rel"] < 1e-11
    # the lecture's pinched extreme s = 3: the normals differ visibly only where Su x Sv
    # nearly vanishes, by exactly what round-off in the derivatives explains
    r = sm.crosscheck(sm.superellipsoid(20, 15, 10, 3.0, 3.0))
    assert r.passed and r.details["normal"] > 1e-9 and r.details["normal_conditioned"] < 1e-12


def test_tighter_tolerance_means_more_samples():
    a = sm.superellipsoid(1, 1, 1, 0.3, 0.3, tolerance=1e-2)
    b = sm.superellipsoid(1, 1, 1, 0.3, 0.3, tolerance=1e-4)
    assert b.samples[0] > a.samples[0] and b.samples[1] > a.samples[1]
    assert a.max_deviation <= 1e-2 and b.max_deviation <= 1e-4


def test_implicit_form_values():
    assert superellipsoid_implicit(2, 2, 2, 0.5, 0.5, 2.0, 0.0, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert superellipsoid_implicit(2, 2, 2, 0.5, 0.5, 0.0, 0.0, 0.0) == pytest.approx(-1.0)
    # a box-like superellipsoid contains the point (0.9, 0.9, 0.9) r, an ellipsoid does not
    assert superellipsoid_implicit(1, 1, 1, 0.1, 0.1, 0.9, 0.9, 0.9) < 0
    assert superellipsoid_implicit(1, 1, 1, 1, 1, 0.9, 0.9, 0.9) > 0


def test_bad_inputs():
    with pytest.raises(sm.SurfmodError, match="rx"):
        sm.superellipsoid(-1, 1, 1, 1, 1)
    with pytest.raises(sm.SurfmodError, match="s1"):
        sm.superellipsoid(1, 1, 1, 0, 1)
    with pytest.raises(sm.SurfmodError, match="s2: exponent must lie"):
        sm.superellipsoid(1, 1, 1, 1, 9)
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.superellipsoid(1, 1, 1, 1, 1, tolerance=1e-12)


def test_unit_exponents_lie_on_the_exact_nurbs_ellipsoid():
    e = sm.ellipsoid(3.0, 2.0, 1.0)
    s = sm.superellipsoid(3.0, 2.0, 1.0, 1.0, 1.0, tolerance=1e-4)
    u, v = _random_uv(1500, 5)
    dist = sm.to_implicit(e).distance_estimate(s.points(u, v))
    assert np.abs(dist).max() <= 1e-4
    # OCCT's area of the fitted face equals the ellipsoid's area (Gauss-Legendre on the
    # analytic parametrization), to the fit's accuracy
    x, w = np.polynomial.legendre.leggauss(200)
    eta, om = x[:, None] * np.pi / 2, x[None, :] * np.pi
    a, b, c = 3.0, 2.0, 1.0
    jac = np.cos(eta) * np.sqrt(
        (b * c * np.cos(eta) * np.cos(om)) ** 2 + (a * c * np.cos(eta) * np.sin(om)) ** 2 + (a * b * np.sin(eta)) ** 2
    )
    exact = float(np.einsum("i,j,ij->", w, w, jac)) * (np.pi / 2) * np.pi
    assert s.face().area == pytest.approx(exact, rel=1e-4)
