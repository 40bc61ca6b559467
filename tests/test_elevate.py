"""Degree elevation in closed form (The NURBS Book, A5.9): OCCT's ``IncreaseDegree`` and the
40-digit evaluation of the original spline are the judges."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from surfmod.nets.bspline import cartesian, homogeneous
from surfmod.nets.elevate import elevate_degree
from surfmod.nets.mp_reference import curve_partials
from surfmod.occ.geom import read_bspline_curve, read_bspline_surface


def _curve(degree, mults, rational, seed=3):
    """A clamped random spline on [0, 1] with interior knots of the given multiplicities."""
    rng = np.random.default_rng(seed)
    inner = np.repeat(np.sort(rng.uniform(0.05, 0.95, len(mults))), mults)
    knots = np.concatenate([np.zeros(degree + 1), inner, np.ones(degree + 1)])
    n = knots.size - degree - 1
    weights = rng.uniform(0.5, 2.0, n) if rational else None
    return sm.BSplineCurve(rng.normal(size=(n, 3)), degree, knots, weights)


def _elevate(curve, times):
    k, h = elevate_degree(curve.knots, curve.degree, homogeneous(curve.control_points, curve.weights), times)
    pts, w = cartesian(h, curve.weights is not None)
    return k, pts, w


@pytest.mark.parametrize("degree, mults, times, rational", [
    (3, [1] * 19, 1, False), (3, [1] * 19, 2, False), (3, [1, 2, 3], 2, True),
    (2, [2, 1, 2], 3, True), (5, [5, 1, 3, 4], 4, False), (1, [1, 1], 6, True)])
def test_curve_matches_occt_increase_degree(degree, mults, times, rational):
    c = _curve(degree, mults, rational)
    k, pts, w = _elevate(c, times)
    g = c.geom()
    g.IncreaseDegree(degree + times)
    ref = read_bspline_curve(g)
    assert ref["degree"] == degree + times
    np.testing.assert_allclose(k, ref["knots"], rtol=0, atol=1e-15)
    scale = np.abs(c.control_points).max()
    np.testing.assert_allclose(pts, ref["points"], rtol=0, atol=1e-12 * scale)
    if rational:
        np.testing.assert_allclose(w, ref["weights"], rtol=1e-12)


@pytest.mark.parametrize("axis", [0, 1])
def test_surface_net_matches_occt_increase_degree(axis):
    rng = np.random.default_rng(5)
    s = sm.BSplineSurface(rng.normal(size=(6, 7, 3)), (2, 3), ([0, 0, 0, 0.3, 0.3, 0.7, 1, 1, 1],
                                                               [0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1]),
                          1 + rng.random((6, 7)))
    times = 3
    k, h = elevate_degree(s.knots[axis], s.degree[axis], s._homogeneous, times, axis=axis)
    pts, w = cartesian(h, True)
    g = s.geom()
    g.IncreaseDegree(s.degree[0] + times * (axis == 0), s.degree[1] + times * (axis == 1))
    ref = read_bspline_surface(g)
    np.testing.assert_allclose(k, ref["knots"][axis], rtol=0, atol=1e-15)
    np.testing.assert_allclose(pts, ref["control_points"], rtol=0, atol=1e-12 * np.abs(s.control_points).max())
    np.testing.assert_allclose(w, ref["weights"], rtol=1e-12)


def _mp_gap(original, knots, pts, w, degree, ts):
    """Largest distance between the original and the elevated spline, both evaluated in
    40 digits from their double control points (so only the elevation's error is left)."""
    gap = 0.0
    for t in ts:
        a = curve_partials(original.control_points, original.weights, original.degree, original.knots, t)[0]
        b = curve_partials(pts, w, degree, knots, t)[0]
        gap = max(gap, max(abs(float(x - y)) for x, y in zip(a, b)))
    return gap


@pytest.mark.parametrize("degree, mults, target", [
    (3, [], 20), (3, [], 28), (3, [1, 2, 3], 9), (4, [1, 2, 3, 4], 8), (2, [1, 2], 12)])
def test_elevated_equals_original_in_forty_digits(degree, mults, target):
    """Collocation at the Greville abscissae left 3e-5 on one span raised from 3 to 28;
    the closed form stays at round-off."""
    c = _curve(degree, mults, rational=False, seed=7)
    k, pts, w = _elevate(c, target - degree)
    gap = _mp_gap(c, k, pts, w, target, np.linspace(0, 1, 23))
    assert gap <= 1e-13 * np.abs(c.control_points).max()


def test_rational_circle_elevated_to_quintic_stays_on_the_circle():
    r = math.sqrt(0.5)
    pts = np.array([(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0)], float)
    circle = sm.BSplineCurve(np.column_stack([pts, np.zeros(9)]), 2, [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4],
                             [1, r, 1, r, 1, r, 1, r, 1])
    k, p5, w5 = _elevate(circle, 3)
    quintic = sm.BSplineCurve(p5, 5, k, w5)
    xyz = quintic.points(np.linspace(0, 4, 401))
    np.testing.assert_allclose(np.hypot(xyz[:, 0], xyz[:, 1]), 1.0, rtol=0, atol=1e-15)
    assert np.all(xyz[:, 2] == 0)
