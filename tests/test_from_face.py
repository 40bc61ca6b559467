"""Reading OCCT / build123d faces and edges back into surfmod objects."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm


def test_build123d_spline_face_reads_back():
    import build123d as bd

    pts = [[(x, y, 0.2 * np.sin(x + y)) for y in range(5)] for x in range(4)]
    face = bd.Face.make_surface_from_array_of_points(pts)
    s = sm.from_face(face)
    assert isinstance(s.surface, sm.BSplineSurface)
    r = sm.crosscheck(face)
    assert r.passed, r.details
    # the surface interpolates the given points somewhere: every point is on it (checked via OCCT)
    assert abs(s.face().area - face.area) < 1e-9 * face.area


def test_trimmed_parameter_range_is_respected(rng):
    s = sm.BSplineSurface(rng.uniform(-1, 1, (6, 5, 3)), (3, 3))
    from surfmod.occ.topo import face_from_surface

    face = face_from_surface(s.geom(), 0.2, 0.7, 0.1, 0.9)
    back = sm.from_face(face)
    assert back.domain == ((0.2, 0.7), (0.1, 0.9))
    np.testing.assert_allclose(back.points(0.5, 0.5), s.points(0.5, 0.5), atol=1e-13)


def test_edges_and_wires_are_curves():
    import build123d as bd

    edge = bd.Edge.make_spline([(0, 0, 0), (1, 1, 0), (2, 0, 1), (3, 1, 1)])
    c = sm.from_edge(edge)
    t0, t1 = c.domain
    np.testing.assert_allclose(c.points(t0), (0, 0, 0), atol=1e-12)
    np.testing.assert_allclose(c.points(t1), (3, 1, 1), atol=1e-12)
    wire = bd.Wire.make_polygon([(0, 0, 0), (1, 0, 0), (1, 1, 0)], close=False)
    cw = sm.from_edge(wire)
    assert abs(cw.length() - 2.0) < 1e-9


def test_not_a_face():
    with pytest.raises(sm.SurfmodError, match="face: expected a build123d Face"):
        sm.from_face(42)
    with pytest.raises(sm.SurfmodError, match="expected a build123d Edge or Wire"):
        sm.from_edge("edge")


# -- faces are trimmed surfaces: operations respect the boundary --------------------------------
def _holed_top():
    import build123d as bd

    plate = bd.Box(4, 3, 1) - bd.Cylinder(0.5, 2)
    return plate.faces().sort_by(bd.Axis.Z)[-1]


def test_the_area_of_a_face_is_from_face_area():
    top = _holed_top()
    assert abs(sm.from_face(top).area() - (12 - np.pi / 4)) < 1e-12
    assert abs(sm.from_face(top).area() - top.area) < 1e-12 * top.area
    with pytest.warns(DeprecationWarning, match="from_face"):  # the old name, for one release
        assert sm.trimmed_area(sm.from_face(top)) == sm.from_face(top).area()
    with pytest.raises(sm.SurfmodError, match="boundary_curve_uv"):
        sm.trimmed_area(sm.sphere(1.0))


def test_intersect_clips_to_the_face_like_brepalgoapi_section():
    from surfmod.occ.sample import edge_length, wire_edges
    from surfmod.occ.booleans import cut_edges, wires_of

    top = _holed_top()
    origin, normal = np.array([0.1, 0.0, 0.0]), np.array([1.0, 0.3, 0.0]) / np.hypot(1.0, 0.3)
    curves = sm.intersect(top, (origin, normal))  # a build123d Face is accepted
    assert len(curves) == 2  # the hole splits the chord
    ref = sum(edge_length(e) for w in wires_of(cut_edges(top.wrapped, origin, normal)) for e in wire_edges(w))
    assert abs(sum(c.length for c in curves) - ref) <= 1e-6 * ref
    # the untrimmed plane would give one chord across the whole 4 x 3 rectangle
    whole = sm.intersect(sm.from_face(top).surface, (origin, normal))
    assert sum(c.length for c in whole) > ref + 0.9


def test_project_measures_the_distance_to_the_face():
    from surfmod.occ.sample import distances_to_face

    top = _holed_top()
    pts = np.array([(0.0, 0.0, 2.0), (0.2, 0.1, 0.9), (5.0, 0.0, 0.5), (1.0, 1.0, 3.0)])
    pr = sm.project(pts, top)
    np.testing.assert_allclose(pr.distance, distances_to_face(top.wrapped, pts), atol=1e-9)
    assert pr.distance[0] == pytest.approx(np.hypot(0.5, 1.5), abs=1e-12)  # to the hole's rim
    np.testing.assert_allclose(np.linalg.norm(pr.point - pts, axis=1), pr.distance, atol=1e-12)
