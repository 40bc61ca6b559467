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


def _short_span_surface(rng):
    """A degree-4 x 1 face of a trimmed STEP part (``examples/trim.py``): a span of 0.0045,
    coordinates near 33 and control points 0.03 apart, so D2 (~50) is a difference of
    differences over 0.0045^2 and both evaluators round it off at about 1e-8."""
    ku = [0] * 5 + [0.004504733009621] * 4 + [0.04230871343658] * 5
    x = np.array([33.003717, 32.972179, 32.940689, 32.909249, 32.877860, 32.614437, 32.354574, 32.098808, 31.847532])
    y = np.array([18.660630, 18.682972, 18.705315, 18.727657, 18.75, 18.9375, 19.13125, 19.33125, 19.5375])
    z = np.array([5.770739, 5.768235, 5.765690, 5.763104, 5.760476, 5.738430, 5.712849, 5.684185, 5.652887])
    bottom = np.stack([x, y, z], axis=-1)
    top = bottom + [-0.155, -0.09, 0.98]
    net = np.stack([bottom, top], axis=1) + rng.uniform(-1e-9, 1e-9, (9, 2, 3))
    return ku, net


def test_short_knot_spans_are_judged_against_their_round_off(rng):
    ku, net = _short_span_surface(rng)
    s = sm.BSplineSurface(net, (4, 1), (ku, [0, 0, 1, 1]))
    r = sm.crosscheck(s, samples=64)
    assert r.passed, r.details


class _BentD2(sm.BSplineSurface):
    """Second u-derivative off by ``bend`` times the surface's own D2 round-off scale x 1e4."""

    bend = 1e-3

    def _derivatives(self, u, v, order):
        out = np.array(super()._derivatives(u, v, order))
        if order >= 2:
            out[:, 2, 0, 2] += self.bend * np.abs(out[:, 2, 0]).max()
        return out


def test_a_wrong_second_derivative_still_fails_on_short_spans(rng):
    ku, net = _short_span_surface(rng)
    s = _BentD2._trusted(net, (4, 1), (ku, [0, 0, 1, 1]))
    r = sm.crosscheck(s, samples=17)
    assert not r.passed and r.details["d2_rel"] > 1e-6


class _TurnedNormal(sm.BezierSurface):
    def normals(self, u, v):
        n = super().normals(u, v) + [1e-6, 0, 0]
        return n / np.linalg.norm(n, axis=-1, keepdims=True)


def test_a_turned_normal_fails_at_regular_points(rng):
    s = _TurnedNormal(rng.uniform(-1, 1, (4, 4, 3)))
    r = sm.crosscheck(s, samples=9)
    assert not r.passed and r.details["normal_conditioned"] > 1e-7


def test_round_off_wide_knot_spans_are_judged_on_positions_only():
    """Knots like ``[-2.9e-11]*4 + [0, 0.059, ...]`` (public NIST models): on the 2.9e-11
    span derivatives are differences of control points over h^k and curvature means
    nothing in any evaluator; the check says so instead of failing."""
    rng = np.random.default_rng(1)
    ku = np.array([-2.9e-11] * 4 + [0.0, 0.059, 0.3, 0.7] + [1.0] * 4)
    kv = np.array([0.0] * 4 + [0.5] + [1.0] * 4)
    net = np.zeros((8, 5, 3))
    net[..., 0], net[..., 1] = np.meshgrid(np.linspace(0, 10, 8), np.linspace(0, 5, 5), indexing="ij")
    net[..., 2] = rng.uniform(-1, 1, (8, 5))
    s = sm.BSplineSurface(net, (3, 3), (ku, kv))
    r = sm.crosscheck(s, samples=24)
    assert r.passed and r.details["failed"] == {}
    assert r.details["short_span_points"] > 0
    assert r.max_deviation < 1e-13
    # the derivative check still bites off the short span: d1 is compared to 1e-10
    assert r.details["d1_rel"] < 1e-12 and r.details["derivative_tolerance"] == 1e-10
