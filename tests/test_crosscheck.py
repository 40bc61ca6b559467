"""sm.crosscheck itself: it passes on exact twins, and it can fail."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm


class _Shifted(sm.BSplineSurface):
    """A surface whose OCCT twin is deliberately off by ``shift`` in z."""

    shift = 1e-9

    def geom(self):
        return sm.BSplineSurface._trusted(self.control_points + [0, 0, self.shift], self.degree, self.knots).geom()


def test_crosscheck_detects_a_tiny_disagreement(rng):
    net = rng.uniform(-1, 1, (4, 4, 3))
    s = _Shifted._trusted(net, (3, 3), sm.BSplineSurface(net, (3, 3)).knots)
    r = sm.crosscheck(s, samples=8)
    assert not r.passed
    assert r.max_deviation == pytest.approx(1e-9, rel=1e-3)


def test_crosscheck_includes_knots_and_ends(rng):
    ku = [0, 0, 0, 0.123, 0.777, 1, 1, 1]
    s = sm.BSplineSurface(rng.uniform(-1, 1, (5, 3, 3)), (2, 2), (ku, [0, 0, 0, 1, 1, 1]))
    r = sm.crosscheck(s, samples=5)
    assert r.samples == (5 + 2) * 5  # two extra knots in u
    assert r.passed and r.mode == "parametric"
    assert set(r.details) >= {"position", "d1_rel", "d2_rel", "normal", "curvature_rel"}


def test_degenerate_edge_gives_the_limit_normal():
    """A Bézier patch with its v=0 edge collapsed to an apex (a cone-like cap):
    Su vanishes there, the normal is the limit from inside and never NaN."""
    apex = np.zeros(3)
    ring = np.array([[1, 0, -1], [1, 1, -1], [0, 1, -1]], dtype=float)
    net = np.stack([np.repeat(apex[None], 3, axis=0), ring * [1, 1, 1]], axis=1)  # (3, 2, 3)
    s = sm.BezierSurface(net)
    n = s.normals(np.linspace(0, 1, 5), 0.0)
    assert np.all(np.isfinite(n))
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0)
    inside = s.normals(np.linspace(0, 1, 5), 1e-4)
    assert np.all(np.einsum("ij,ij->i", n, inside) > 0.999)
    c = s.curvatures(0.5, 0.0)
    assert all(np.isfinite(x) for x in c)
    assert sm.crosscheck(s, samples=9).passed


def test_crosscheck_of_curves_and_faces(rng):
    c = sm.BSplineCurve(rng.uniform(-1, 1, (6, 3)), 3, weights=rng.uniform(0.5, 2, 6))
    assert sm.crosscheck(c).passed
    s = sm.BezierSurface(rng.uniform(-1, 1, (3, 4, 3)))
    r = sm.crosscheck(s.face())
    assert r.passed and r.mode == "parametric"
