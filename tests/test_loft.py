"""Lofts through sections against BRepOffsetAPI_ThruSections and closed forms."""

import numpy as np
import pytest

import surfmod as sm

A = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 0.5, 0)], 3)
B = sm.BSplineCurve([(0, 0, 2), (1, -1, 2), (2, 0, 2)], 2)
C = sm.BSplineCurve([(0, 0.5, 4), (1, 1, 4.5), (2, 0, 4), (3, 1, 4), (4, 0, 4)], 3)
D = sm.Line((0, 0, 6), (4, 0, 6))


@pytest.mark.parametrize("count", [2, 3, 4])
@pytest.mark.parametrize("ruled", [False, True])
def test_matches_thru_sections(count, ruled):
    secs = [A, B, C, D][:count]
    s = sm.loft(secs, ruled=ruled)
    r = sm.crosscheck(s, samples=12)
    assert r.passed and r.max_deviation < 1e-9, r
    assert s.occt_deviation(12) < 1e-9
    # every section is reproduced exactly at its parameter
    for sec, v in zip(secs, s.section_parameters):
        t0, t1 = sec.domain
        u = np.linspace(0, 1, 9)
        (a, b), _ = s.domain
        assert np.abs(s.points(a + u * (b - a), v) - sec.points(t0 + u * (t1 - t0))).max() < 1e-12


def test_many_sections_and_degree():
    rng = np.random.default_rng(0)
    secs = [
        sm.BSplineCurve(np.column_stack([np.linspace(0, 3, 5), rng.normal(0, 0.2, 5), np.full(5, 2.0 * k)]), 3)
        for k in range(6)
    ]
    s = sm.loft(secs)
    assert s.degree == (3, 5)
    assert s.occt_deviation(10) < 1e-9


def test_ruled_is_linear_between_sections():
    s = sm.loft([A, D], ruled=True)
    (u0, u1), (v0, v1) = s.domain
    u = np.linspace(u0, u1, 7)
    for t in (0.25, 0.5):
        expect = (1 - t) * s.points(u, v0) + t * s.points(u, v1)
        assert np.abs(s.points(u, v0 + t * (v1 - v0)) - expect).max() < 1e-12


def test_circles_give_an_exact_surface_of_revolution():
    import build123d as bd

    c1 = bd.Edge.make_circle(1.0)
    c2 = bd.Edge.make_circle(2.0, bd.Plane.XY.offset(3))
    c3 = bd.Edge.make_circle(1.0, bd.Plane.XY.offset(6))
    s = sm.loft([c1, c2, c3])
    assert s.rational
    g = s.grid(np.linspace(*s.domain[0], 25), np.linspace(*s.domain[1], 13))
    # every v-section is a circle about the z axis (rotational symmetry of the data)
    r = np.hypot(g[..., 0], g[..., 1])
    assert np.abs(r - r[:1]).max() < 1e-12
    assert sm.crosscheck(s, samples=12).max_deviation < 1e-9


def test_bad_inputs():
    with pytest.raises(sm.SurfmodError, match=r"sections\[1\]: runs opposite"):
        sm.loft([A, sm.BSplineCurve(B.control_points[::-1], 2)])
    import build123d as bd

    circle = bd.Edge.make_circle(1.0, bd.Plane.XY.offset(2))
    with pytest.raises(sm.SurfmodError, match=r"sections\[1\]: is closed while sections\[0\] is open"):
        sm.loft([A, circle])
    reversed_circle = bd.Edge.make_circle(1.0, bd.Plane.XY.offset(4).reverse())
    with pytest.raises(sm.SurfmodError, match=r"sections\[1\]: runs the opposite way round"):
        sm.loft([bd.Edge.make_circle(1.0), reversed_circle])
    with pytest.raises(sm.SurfmodError, match="sections: a loft needs at least 2"):
        sm.loft([A])
    with pytest.raises(sm.SurfmodError, match=r"sections\[1\]: coincides"):
        sm.loft([A, A])
    with pytest.raises(sm.SurfmodError, match=r"sections\[0\]"):
        sm.loft(["A", B])


def test_rational_sections_of_different_shape_match_occt():
    import build123d as bd

    duct = [
        bd.Edge.make_circle(10),
        bd.Edge.make_ellipse(16, 8, bd.Plane.XY.offset(25)),
        bd.Edge.make_circle(6, bd.Plane.XY.offset(50)),
    ]
    s = sm.loft(duct)
    assert s.rational
    r = sm.crosscheck(s, samples=12)
    assert r.passed and r.max_deviation < 1e-9
