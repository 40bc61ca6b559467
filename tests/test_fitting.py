"""Interpolation vs approximation surfaces: against OCCT's GeomAPI_PointsToBSplineSurface
and against the textbook facts (interpolation reproduces the data and polynomials)."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.construct.fitting import approximation_knots, averaging_knots, grid_parameters


def _grid(n, m, warp=0.0):
    x, y = np.meshgrid(np.linspace(0, 3, n), np.linspace(0, 2, m), indexing="ij")
    return np.stack([x + warp * y**2, y + 0.1 * x**2, np.sin(x) * np.cos(y)], axis=-1)


@pytest.mark.parametrize("method", ["chord", "centripetal", "uniform"])
def test_interpolate_passes_through_points(method):
    pts = _grid(9, 7, warp=0.2)
    s = sm.interpolate(pts, degree=(3, 3), method=method)
    assert s.control_points.shape == (9, 7, 3)
    us, vs = s.parameters
    assert np.abs(s.grid(us, vs) - pts).max() < 1e-13
    assert s.max_deviation < 1e-13
    assert sm.crosscheck(s, samples=12).passed  # the spline is its OCCT twin


def test_parameters_and_knots_follow_piegl_tiller():
    pts = _grid(6, 5)
    us = grid_parameters(pts, 0, "chord")
    # P&T eq. 9.5/9.6 written out: per column chord length, then the mean
    cols = []
    for j in range(5):
        d = np.linalg.norm(np.diff(pts[:, j], axis=0), axis=1)
        cols.append(np.concatenate([[0], np.cumsum(d)]) / d.sum())
    assert np.allclose(us, np.mean(cols, axis=0), atol=1e-15)
    k = averaging_knots(us, 3)
    assert np.allclose(k[4:-4], [(us[1] + us[2] + us[3]) / 3, (us[2] + us[3] + us[4]) / 3], atol=1e-15)
    ka = approximation_knots(np.linspace(0, 1, 20), 3, 6)
    assert ka.size == 10 and np.all(np.diff(ka) >= 0)


def test_interpolation_reproduces_cubic_polynomial_surfaces():
    # a bicubic polynomial graph lies in the spline space: interpolation is exact everywhere
    x, y = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 1, 6), indexing="ij")
    f = lambda x, y: x**3 - 2 * x * y**2 + y**3 + 0.5
    pts = np.stack([x, y, f(x, y)], axis=-1)
    s = sm.interpolate(pts, parameters=(x[:, 0], y[0]))
    u = np.linspace(0, 1, 23)
    g = s.grid(u, u)
    assert np.abs(g[..., 2] - f(u[:, None], u[None, :])).max() < 1e-13


def test_interpolate_matches_occt_on_the_data():
    pts = _grid(10, 8, warp=0.1)
    s = sm.interpolate(pts)
    geom, occ_err = s.occt_fit()
    assert s.max_deviation < 1e-10 and occ_err < 1e-10


def test_approximate_within_tolerance_and_smaller_than_interpolation():
    pts = _grid(40, 30)
    a = sm.approximate(pts, tolerance=1e-4)
    assert a.max_deviation <= 1e-4
    n, m = a.control_points.shape[:2]
    assert n < 40 and m < 30
    us, vs = a.parameters
    assert np.isclose(np.linalg.norm(a.grid(us, vs) - pts, axis=-1).max(), a.max_deviation, rtol=1e-12)
    geom, occ_err = a.occt_fit()
    assert occ_err <= 1e-4


def test_approximate_with_fixed_control_count_is_least_squares():
    pts = _grid(15, 12)
    a = sm.approximate(pts, n_ctrl=(6, 5))
    assert a.control_points.shape == (6, 5, 3)
    # least squares: perturbing any control point cannot decrease the squared residual
    us, vs = a.parameters
    base = np.sum((a.grid(us, vs) - pts) ** 2)
    for i, j in [(0, 0), (2, 3), (5, 4)]:
        net = a.control_points.copy()
        net[i, j, 2] += 1e-3
        b = sm.BSplineSurface(net, a.degree, a.knots)
        assert np.sum((b.grid(us, vs) - pts) ** 2) > base


def test_fewer_points_than_degree_needs():
    with pytest.raises(sm.SurfmodError, match="points: degree 3 in u needs at least 4 rows"):
        sm.interpolate(_grid(3, 6))
    with pytest.raises(sm.SurfmodError, match="points: degree 3 in v needs at least 4 columns"):
        sm.approximate(_grid(6, 2), tolerance=1e-3)


def test_bad_inputs_named():
    with pytest.raises(sm.SurfmodError, match="points"):
        sm.interpolate(np.zeros((4, 4, 2)))
    with pytest.raises(sm.SurfmodError, match="method"):
        sm.interpolate(_grid(5, 5), method="foley")
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.approximate(_grid(8, 8), tolerance=-1)
    with pytest.raises(sm.SurfmodError, match="n_ctrl"):
        sm.approximate(_grid(8, 8), n_ctrl=(9, 4))
    pts = _grid(5, 5)
    pts[2] = pts[1]
    with pytest.raises(sm.SurfmodError, match="points: consecutive points coincide"):
        sm.interpolate(pts)
    with pytest.raises(sm.SurfmodError, match="points"):
        sm.interpolate(np.full((5, 5, 3), np.nan))


from hypothesis import given, settings, strategies as st


@settings(max_examples=25, deadline=None)
@given(
    p=st.integers(1, 5),
    q=st.integers(1, 5),
    n_extra=st.integers(0, 6),
    m_extra=st.integers(0, 6),
    method=st.sampled_from(["chord", "centripetal", "uniform"]),
    seed=st.integers(0, 2**16),
)
def test_interpolation_property(p, q, n_extra, m_extra, method, seed):
    rng = np.random.default_rng(seed)
    n, m = p + 1 + n_extra, q + 1 + m_extra
    x, y = np.meshgrid(np.cumsum(rng.uniform(0.2, 1, n)), np.cumsum(rng.uniform(0.2, 1, m)), indexing="ij")
    pts = np.stack([x, y, rng.normal(size=(n, m))], axis=-1)
    s = sm.interpolate(pts, degree=(p, q), method=method)
    assert s.degree == (p, q) and s.control_points.shape == (n, m, 3)
    scale = np.abs(pts).max()
    assert s.max_deviation <= 1e-9 * scale
    # the approximation with the full control count is the interpolation
    a = sm.approximate(pts, degree=(p, q), n_ctrl=(n, m), method=method)
    assert np.abs(a.control_points - s.control_points).max() <= 1e-7 * np.abs(s.control_points).max()
