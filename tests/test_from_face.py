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
