"""Exact sub-patches by knot insertion (segment/split) vs OCCT's Geom_BSplineSurface::Segment."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import surfmod as sm
from strategies import bspline_surfaces
from surfmod.occ.geom import downcast_surface, read_bezier_surface, read_bspline_surface
from surfmod.occ.sample import surface_d0


def segmented(surf, u0: float, u1: float, v0: float, v1: float):
    """A copy of a B-spline or Bézier ``surf`` cut down by OCCT's ``Segment``: the twin."""
    out = downcast_surface(surf.Copy())
    out.Segment(float(u0), float(u1), float(v0), float(v1))
    return out


def _size(s):
    return max(1.0, float(np.abs(s.control_points).max()))


def _assert_equal_to_occt_segment(s, ur, vr):
    mine = s.segment(ur, vr)
    theirs = read_bspline_surface(segmented(s.geom(), *ur, *vr))
    np.testing.assert_array_equal(mine.knots[0], theirs["knots"][0])
    np.testing.assert_array_equal(mine.knots[1], theirs["knots"][1])
    assert mine.degree == theirs["degree"]
    np.testing.assert_allclose(mine.control_points, theirs["control_points"], rtol=0, atol=1e-12 * _size(s))
    if s.rational:
        np.testing.assert_allclose(mine.weights, theirs["weights"], rtol=1e-12)
    # same points as the parent over the sub-domain
    assert mine.domain == (tuple(ur), tuple(vr))
    uu, vv = np.meshgrid(np.linspace(*ur, 7), np.linspace(*vr, 7), indexing="ij")
    np.testing.assert_allclose(mine.points(uu, vv), s.points(uu, vv), rtol=0, atol=1e-12 * _size(s))
    return mine


def test_uniform_cubic_unclamped_segment_matches_occt():
    rng = np.random.default_rng(0)
    s = sm.BSplineSurface.uniform_cubic(rng.uniform(-1, 1, (7, 6, 3)))
    assert s.domain == ((0.0, 4.0), (0.0, 3.0))
    mine = _assert_equal_to_occt_segment(s, (0.3, 2.5), (1.0, 2.2))
    # clamped result: end knots of multiplicity degree + 1, the inner knots kept
    np.testing.assert_array_equal(mine.knots[0], [0.3] * 4 + [1.0, 2.0] + [2.5] * 4)
    np.testing.assert_array_equal(mine.knots[1], [1.0] * 4 + [2.0] + [2.2] * 4)


def test_rational_segment_matches_occt():
    rng = np.random.default_rng(1)
    s = sm.BSplineSurface(rng.uniform(-1, 1, (7, 6, 3)), (3, 2), None, rng.uniform(0.2, 5, (7, 6)))
    _assert_equal_to_occt_segment(s, (0.3, 0.5), (0.25, 0.6))
    # ends on existing knots, and the full domain (identity)
    _assert_equal_to_occt_segment(s, (0.25, 0.75), (0.0, 1.0))
    full = s.segment((0.0, 1.0), (0.0, 1.0))
    np.testing.assert_allclose(full.control_points, s.control_points, atol=1e-15)


def test_bezier_segment_is_exact_and_equals_occt_bezier_segment():
    rng = np.random.default_rng(2)
    b = sm.BezierSurface(rng.uniform(-1, 1, (4, 5, 3)), rng.uniform(0.5, 2, (4, 5)))
    piece = b.segment((0.2, 0.7), (0.1, 0.9))
    theirs = read_bezier_surface(segmented(b.geom(), 0.2, 0.7, 0.1, 0.9))
    # OCCT reparametrizes its Bézier segment to [0, 1]^2; the control net is the same
    np.testing.assert_allclose(piece.control_points, theirs["control_points"], atol=1e-14)
    np.testing.assert_allclose(piece.weights, theirs["weights"], rtol=1e-13)
    s, t = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6), indexing="ij")
    geom = segmented(b.geom(), 0.2, 0.7, 0.1, 0.9)
    np.testing.assert_allclose(
        piece.points(0.2 + 0.5 * s, 0.1 + 0.8 * t).reshape(-1, 3), surface_d0(geom, s.ravel(), t.ravel()), atol=1e-14
    )


def test_split_into_four_pieces_covers_the_patch():
    rng = np.random.default_rng(3)
    s = sm.BSplineSurface(rng.uniform(-1, 1, (6, 6, 3)), (3, 3), None, rng.uniform(0.5, 2, (6, 6)))
    pieces = s.split(u=0.4, v=0.5)
    assert [p.domain for p in pieces] == [
        ((0.0, 0.4), (0.0, 0.5)),
        ((0.0, 0.4), (0.5, 1.0)),
        ((0.4, 1.0), (0.0, 0.5)),
        ((0.4, 1.0), (0.5, 1.0)),
    ]
    for p in pieces:
        (a, b), (c, d) = p.domain
        _assert_equal_to_occt_segment(s, (a, b), (c, d))
    # the shared edge is the same curve on both sides (C0 across the split, exactly)
    v = np.linspace(0, 0.5, 9)
    np.testing.assert_allclose(pieces[0].points(0.4, v), pieces[2].points(0.4, v), atol=1e-14)
    assert len(s.split(u=0.4)) == 2 and len(s.split(v=0.1)) == 2


def _inside(lo, hi, f):
    return lo + (hi - lo) * f


@settings(max_examples=40, deadline=None)
@given(
    s=bspline_surfaces(max_degree=5),
    f=st.lists(st.floats(0.0, 1.0), min_size=4, max_size=4).map(lambda x: np.round(x, 3)),
)
def test_random_segments_match_occt(s, f):
    (u0, u1), (v0, v1) = s.domain
    fu, fv = np.sort(f[:2]), np.sort(f[2:])
    if fu[1] - fu[0] < 0.01 or fv[1] - fv[0] < 0.01:
        return
    ur = (float(_inside(u0, u1, fu[0])), float(_inside(u0, u1, fu[1])))
    vr = (float(_inside(v0, v1, fv[0])), float(_inside(v0, v1, fv[1])))
    # OCCT snaps segment ends lying within ~1e-9 of a knot; keep the ends clear of that
    near = lambda t, k: np.any((np.abs(k - t) < 1e-6) & (k != t))  # noqa: E731
    if any(near(t, s.knots[0]) for t in ur) or any(near(t, s.knots[1]) for t in vr):
        return
    _assert_equal_to_occt_segment(s, ur, vr)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda s: s.segment((0.5, 0.2)), "u_range"),
        (lambda s: s.segment((0.2,)), "u_range"),
        (lambda s: s.segment(None, (0.0, 1.5)), "v_range"),
        (lambda s: s.segment((np.nan, 0.5)), "u_range"),
        (lambda s: s.split(u=1.0), "u"),
        (lambda s: s.split(v=-0.5), "v"),
        (lambda s: s.split(u="middle"), "u"),
        (lambda s: s.split(u=[0.2, 0.3]), "u"),
    ],
)
def test_bad_segment_input(call, match):
    s = sm.BSplineSurface(np.random.default_rng(4).uniform(-1, 1, (4, 4, 3)), (3, 3))
    with pytest.raises(sm.SurfmodError, match=match):
        call(s)
