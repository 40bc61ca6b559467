"""Intersections by marching on the NumPy evaluator vs GeomAPI_IntSS / GeomAPI_IntCS and
closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.Geom import Geom_Plane
from OCP.gp import gp_Dir, gp_Pnt

import surfmod as sm
from twins.geomapi import intersect_line, intersect_surfaces
from surfmod.ops.intersect import as_plane
from surfmod.ops.marching import segment_distances


def _nurbs():
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.linspace(0, 4, 7), np.linspace(0, 3, 6), indexing="ij")
    net = np.stack([x, y, rng.uniform(-1, 1, (7, 6))], -1)
    return sm.BSplineSurface(net, (3, 3), None, rng.uniform(0.5, 2, (7, 6)))


def _wavy():
    x, y = np.meshgrid(np.linspace(-0.5, 4.5, 6), np.linspace(-0.5, 3.5, 6), indexing="ij")
    return sm.BSplineSurface(np.stack([x, y, 0.3 * np.sin(x * 2) + 0.2 * y - 0.3], -1), (3, 3))


def _on_surface(s, uv, pts, tol):
    np.testing.assert_allclose(s.points(uv[:, 0], uv[:, 1]), pts, rtol=0, atol=tol)


def _match_occt(curves, occ_curves, surfaces):
    """Every OCCT curve has a surfmod curve of the same length whose polyline passes
    through the OCCT points; OCCT points lie on both surfaces."""
    for pts, length in occ_curves:
        for s in surfaces:
            assert sm.project(pts, s).distance.max() < 1e-6
        mine = min(curves, key=lambda c: abs(c.length - length))
        assert mine.length == pytest.approx(length, rel=1e-6)
        # OCCT points to our polyline: within the polyline's chordal error
        assert segment_distances(pts, mine.points).max() < 2e-3


def test_surface_plane_matches_intss():
    s = _nurbs()
    origin, normal = np.array([2, 1.5, 0.1]), np.array([0.3, 0.2, 1.0])
    curves = sm.intersect(s, (origin, normal))
    theirs = intersect_surfaces(s.geom(), Geom_Plane(gp_Pnt(*origin), gp_Dir(*normal)))
    assert len(curves) == len(theirs) == 2
    n = normal / np.linalg.norm(normal)
    for c in curves:
        _on_surface(s, c.uv_a, c.points, 1e-15)
        assert np.abs((c.points - origin) @ n).max() < 1e-12  # on the plane
        assert not c.closed
        # ends on the patch boundary
        ends = c.uv_a[[0, -1]]
        assert np.all(np.min(np.abs(np.concatenate([ends, 1 - ends], 1)), axis=1) < 1e-12)
        # uv_b are coordinates in the plane's frame
        o, x, y, _ = sm.intersect.__globals__["plane_frame"](origin, n)
        np.testing.assert_allclose(o + c.uv_b[:, :1] * x + c.uv_b[:, 1:] * y, c.points, atol=1e-12)
    _match_occt(curves, theirs, [s])


def test_surface_surface_matches_intss_and_finds_a_loop_occt_misses():
    a, b = _nurbs(), _wavy()
    curves = sm.intersect(a, b)
    theirs = intersect_surfaces(a.geom(), b.geom())
    for c in curves:
        _on_surface(a, c.uv_a, c.points, 1e-15)
        _on_surface(b, c.uv_b, c.points, 1e-12)
    _match_occt(curves, theirs, [a, b])
    # a small closed loop (about 0.2 x 0.3) that GeomAPI_IntSS does not report
    loops = [c for c in curves if c.closed]
    assert len(curves) == 4 and len(theirs) == 3 and len(loops) == 1
    np.testing.assert_array_equal(loops[0].points[0], loops[0].points[-1])
    assert min(segment_distances(loops[0].points, t[0]).min() for t in theirs) > 0.5


def test_sphere_like_closed_form_circle():
    """A bilinear plane z = 0 cut by the plane x = 0.3: a straight segment of known length;
    a rational quadratic cylinder patch cut by a plane z = c: an exact circular arc."""
    p = sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0))
    [c] = sm.intersect(p, ((0.3, 0, 0), (1, 0, 0)))
    assert c.length == pytest.approx(3.0, rel=1e-14)
    # quarter cylinder x^2 + y^2 = 4, z in [0, 5] as an exact NURBS
    w = np.array([1, 2**-0.5, 1])
    arc = np.array([[2, 0], [2, 2], [0, 2]], float)
    net = np.stack([np.c_[arc, np.full(3, z)] for z in (0.0, 5.0)], axis=1)  # (3, 2, 3)
    cyl = sm.BSplineSurface(net, (2, 1), ([0, 0, 0, 1, 1, 1], [0, 0, 1, 1]), np.stack([w, w], 1))
    [arc_curve] = sm.intersect(cyl, ((0, 0, 1.7), (0, 0, 1)))
    assert arc_curve.length == pytest.approx(np.pi, rel=2e-8)  # quarter of 2 pi * 2 (Hermite length)
    assert np.abs(np.linalg.norm(arc_curve.points[:, :2], axis=1) - 2).max() < 1e-12
    # two surfaces: the cylinder and a tilted plane patch through it -> a quarter ellipse
    tilted = sm.plane((-1, -1, 1.0), (4, -1, 3.5), (-1, 4, 1.0))
    [ell] = sm.intersect(cyl, tilted)
    ts = np.linspace(0, np.pi / 2, 4001)
    x, y = 2 * np.cos(ts), 2 * np.sin(ts)
    z = 1.0 + 0.5 * (x + 1)
    exact = np.sum(np.linalg.norm(np.diff(np.c_[x, y, z], axis=0), axis=1))
    assert ell.length == pytest.approx(exact, rel=1e-7)


def test_empty_intersections_are_empty():
    s = _nurbs()
    assert sm.intersect(s, ((0, 0, 10), (0, 0, 1))) == []
    assert sm.intersect(s, s.translated((0, 0, 10))) == []
    assert sm.intersect(((0, 0, 10), (0, 0, 1)), s) == []
    assert sm.intersect_line(s, (0, 0, 10), (1, 0, 0)).shape == (0, 3)
    assert sm.intersect_line(s, (-10, -10, 0), (-1, 0, 0)).shape == (0, 3)


def test_plane_first_swaps_uv():
    s = _nurbs()
    plane = ((2, 1.5, 0.1), (0.3, 0.2, 1.0))
    a = sm.intersect(s, plane)
    b = sm.intersect(plane, s)
    assert len(a) == len(b)
    for ca, cb in zip(a, b):
        np.testing.assert_array_equal(ca.uv_a, cb.uv_b)


def test_intersect_line_matches_intcs():
    s = _nurbs()
    rng = np.random.default_rng(5)
    hits = 0
    for _ in range(8):
        origin = np.r_[rng.uniform(0.5, 3.5), rng.uniform(0.5, 2.5), 3.0]
        direction = np.r_[rng.uniform(-0.3, 0.3, 2), -1.0]
        mine = sm.intersect_line(s, origin, direction)
        theirs = intersect_line(s.geom(), origin, direction / np.linalg.norm(direction))
        theirs = theirs[np.argsort(theirs[:, 2])]
        assert mine.shape == theirs.shape
        hits += len(mine)
        np.testing.assert_allclose(mine, theirs, atol=1e-9)
        hit = origin + mine[:, 2:] * direction / np.linalg.norm(direction)
        np.testing.assert_allclose(s.points(mine[:, 0], mine[:, 1]), hit, atol=1e-12)
    assert hits >= 5


def test_intersect_line_several_hits():
    """A line through the wavy surface along its waves crosses it several times."""
    w = _wavy()
    mine = sm.intersect_line(w, (-0.4, 1.0, -0.1), (1, 0, 0.02))
    theirs = intersect_line(w.geom(), (-0.4, 1.0, -0.1), np.array([1, 0, 0.02]) / np.linalg.norm([1, 0, 0.02]))
    assert len(mine) == len(theirs) >= 2
    np.testing.assert_allclose(mine, theirs[np.argsort(theirs[:, 2])], atol=1e-9)
    assert np.all(np.diff(mine[:, 2]) > 0)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda s: sm.intersect_line(s, (0, 0, 0), (0, 0, 0)), "direction"),
        (lambda s: sm.intersect_line(s, (0, np.nan, 0), (0, 0, 1)), "origin"),
        (lambda s: sm.intersect_line("s", (0, 0, 0), (0, 0, 1)), "s: expected"),
        (lambda s: sm.intersect(s, ((0, 0, 0), (0, 0, 0))), "normal"),
        (lambda s: sm.intersect(s, ((0, 0, np.nan), (0, 0, 1))), "origin"),
        (lambda s: sm.intersect(s, 42), "b: expected a plane"),
        (lambda s: sm.intersect("a", s), "a: expected a surfmod Surface"),
        (lambda s: sm.intersect(s, s, tolerance=0), "tolerance"),
        (lambda s: sm.intersect(s, s, step=-1), "step"),
        (lambda s: sm.intersect(s, s, max_angle=np.nan), "max_angle"),
    ],
)
def test_bad_intersect_input(call, match):
    with pytest.raises(sm.SurfmodError, match=match):
        call(_nurbs())


def test_quadrics_closed_forms():
    """Sphere and torus (analytic, periodic): plane sections are circles of known length,
    the pole of the sphere is one line hit, not one per meridian."""
    sphere = sm.sphere(2.0)
    [c] = sm.intersect(sphere, ((0, 0, 1), (0, 0, 1)))  # leaves and re-enters through the seam
    assert c.closed and np.linalg.norm(c.points[0] - c.points[-1]) < 1e-9
    assert {round(c.uv_a[0, 0] % (2 * np.pi), 9), round(c.uv_a[-1, 0] % (2 * np.pi), 9)} == {0.0}
    assert c.length == pytest.approx(2 * np.pi * np.sqrt(3), rel=1e-7)
    assert np.abs(np.linalg.norm(c.points, axis=1) - 2).max() < 1e-12
    assert np.abs(c.points[:, 2] - 1).max() < 1e-12
    torus = sm.torus(3.0, 1.0)
    circles = sm.intersect(torus, ((0, 0, 0), (1, 0, 0)))
    assert len(circles) == 2 and all(k.closed for k in circles)
    for k in circles:
        assert k.length == pytest.approx(2 * np.pi, rel=1e-7)
    hits = sm.intersect_line(sphere, (0, 0, 5), (0, 0, -1))
    assert hits.shape == (2, 3)
    np.testing.assert_allclose(hits[:, 2], [3.0, 7.0], atol=1e-12)
    np.testing.assert_allclose(np.abs(hits[:, 1]), np.pi / 2, atol=1e-12)
    theirs = intersect_line(sphere.geom(), (0.3, 0.2, 5), np.array([0.1, 0, -1]) / np.linalg.norm([0.1, 0, -1]))
    mine = sm.intersect_line(sphere, (0.3, 0.2, 5), (0.1, 0, -1))
    np.testing.assert_allclose(mine, theirs[np.argsort(theirs[:, 2])], atol=1e-9)


def test_intersection_curve_as_polyline_bspline():
    [c] = sm.intersect(sm.sphere(2.0), ((0, 0, 1), (0, 0, 1)))
    poly = c.polyline()
    assert poly.degree == 1 and len(poly.control_points) == len(c)
    np.testing.assert_allclose(poly.points(np.array([0.0, 1.0])), c.points[[0, -1]], atol=1e-15)
    # the polyline is shorter than the curve by the chordal error only
    assert 0 < c.length - poly.length(samples=4 * len(c)) < 1e-3 * c.length
    assert c.tangents.shape == c.points.shape
    np.testing.assert_allclose(np.linalg.norm(c.tangents, axis=1), 1.0, atol=1e-14)


def test_plane_surfaces_stand_for_their_infinite_carrier_plane():
    # both plane types (OCCT's frame plane and the three-point plane) give the same plane as
    # (origin, normal) does: the z = 1.7 cut of the quarter cylinder is a quarter circle
    w = np.array([1, 2**-0.5, 1])
    arc = np.array([[2, 0], [2, 2], [0, 2]], float)
    net = np.stack([np.c_[arc, np.full(3, z)] for z in (0.0, 5.0)], axis=1)
    cyl = sm.BSplineSurface(net, (2, 1), ([0, 0, 0, 1, 1, 1], [0, 0, 1, 1]), np.stack([w, w], 1))
    frame_plane = sm.PlaneSurface((9, 9, 1.7), (0, 0, 2), u_range=(0, 0.1), v_range=(0, 0.1))
    three_point = sm.plane((9, 9, 1.7), (9.1, 9, 1.7), (9, 9.1, 1.7))
    for carrier in (frame_plane, three_point):
        origin, normal = as_plane(carrier, "plane")
        assert np.array_equal(origin, [9, 9, 1.7]) and np.allclose(normal, [0, 0, 1], atol=1e-15, rtol=0)
    [reference] = sm.intersect(cyl, ((0, 0, 1.7), (0, 0, 1)))
    [by_frame] = sm.intersect(cyl, ((9, 9, 1.7), (0, 0, 1)))
    assert by_frame.length == pytest.approx(reference.length, rel=1e-12)
    assert np.abs(np.linalg.norm(by_frame.points[:, :2], axis=1) - 2).max() < 1e-12
