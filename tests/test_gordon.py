"""Gordon surfaces: network curves on the surface (measured by OCCT projection),
reproduction of surfaces in the Gordon space, comparison with build123d's Gordon."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm


def _base(seed=0):
    rng = np.random.default_rng(seed)
    net = np.zeros((6, 5, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:6, 0:5]
    net[..., 2] = rng.normal(0, 0.5, (6, 5))
    ku = np.array([0, 0, 0, 0, 0.4, 0.7, 1, 1, 1, 1.0])
    return sm.BSplineSurface(net, (3, 2), (ku, sm.BSplineSurface(net, (3, 2)).knots[1]))


def _spline(pts):
    import build123d as bd

    return bd.Edge.make_spline([bd.Vector(*p) for p in pts])


def _height(x, y):
    return 0.5 * np.sin(x) * np.cos(0.7 * y) + 0.1 * x * y


def _spline_network():
    ys, xs = [0, 1.5, 3], [0, 1, 2.5, 4]
    profiles = [_spline([(x, y, _height(x, y)) for x in np.linspace(0, 4, 9)]) for y in ys]
    guides = [_spline([(x, y, _height(x, y)) for y in np.linspace(0, 3, 7)]) for x in xs]
    return profiles, guides


def test_isocurve_network_is_exact():
    base = _base()
    vs, us = (0.0, 0.3, 0.6, 1.0), (0.0, 0.25, 0.5, 0.8, 1.0)
    profiles = [base.isocurve(v=t) for t in vs]
    guides = [base.isocurve(u=t) for t in us]
    s = sm.gordon(profiles, guides, 1e-6)
    assert not s.reparametrized
    np.testing.assert_allclose(s.parameters[0], us, atol=1e-15)
    np.testing.assert_allclose(s.parameters[1], vs, atol=1e-15)
    t = np.linspace(0, 1, 41)
    for v, c in zip(vs, profiles):
        assert np.abs(s.points(t, v) - c.points(t)).max() <= 1e-13
    for u, c in zip(us, guides):
        assert np.abs(s.points(u, t) - c.points(t)).max() <= 1e-13
    assert s.network_deviation() <= 1e-12
    assert sm.crosscheck(s, samples=12).passed


def test_reproduces_a_surface_inside_the_gordon_space():
    # a bicubic Bezier patch: 4 iso-curves each way span its space, so S == base
    rng = np.random.default_rng(3)
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    net[..., 2] = rng.normal(0, 1, (4, 4))
    base = sm.BSplineSurface(net, (3, 3))
    t = (0.0, 0.3, 0.7, 1.0)
    s = sm.gordon([base.isocurve(v=x) for x in t], [base.isocurve(u=x) for x in t], 1e-9)
    uu, vv = np.meshgrid(np.linspace(0, 1, 13), np.linspace(0, 1, 13))
    assert np.abs(s.points(uu, vv) - base.points(uu, vv)).max() <= 1e-12 * np.abs(net).max()


def test_curve_order_and_direction_of_the_lists_do_not_matter():
    base = _base(1)
    profiles = [base.isocurve(v=t) for t in (0.0, 0.5, 1.0)]
    guides = [base.isocurve(u=t) for t in (0.0, 0.4, 1.0)]
    a = sm.gordon(profiles, guides, 1e-6)
    b = sm.gordon(profiles[::-1], [guides[1], guides[2], guides[0]], 1e-6)
    np.testing.assert_allclose(a.control_points, b.control_points, atol=1e-14)


def test_general_network_within_tolerance_and_vs_build123d():
    profiles, guides = _spline_network()
    tol = 1e-3
    s = sm.gordon(profiles, guides, tol)
    assert s.reparametrized
    ours = s.network_deviation(64)
    assert ours <= tol
    # build123d's Gordon (ocp_gordon) on the same edges meets the same tolerance
    face = s.occt_gordon()
    from surfmod.occ.filling import curve_to_surface_distances
    from surfmod.occ.topo import face_surface

    geom, bounds, _ = face_surface(face)
    theirs = max(float(np.nanmax(curve_to_surface_distances(geom, bounds, sm.from_edge(e).geom(), 64)))
                 for e in (*profiles, *guides))
    assert theirs <= tol
    # continuity: no interior knot of ours is repeated beyond degree - 2 (C2 like theirs)
    for knots, p in zip(s.knots, s.degree):
        inner = knots[(knots > knots[0]) & (knots < knots[-1])]
        assert np.unique(inner, return_counts=True)[1].max(initial=0) <= p - 2


def test_errors_name_the_curves():
    profiles, guides = _spline_network()
    with pytest.raises(sm.SurfmodError, match=r"guides\[\d\]: does not cross profiles"):
        sm.gordon(profiles, [*guides[:-1], guides[-1].translate((0, 0, 0.5))], 1e-3)
    with pytest.raises(sm.SurfmodError, match="profiles: a Gordon surface needs at least 2"):
        sm.gordon(profiles[:1], guides, 1e-3)
    with pytest.raises(sm.SurfmodError, match=r"guides\[1\]: expected a surfmod curve"):
        sm.gordon(profiles, [guides[0], 5, guides[2]], 1e-3)
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.gordon(profiles, guides, -1.0)
    # a guide network that stops short of the last profile
    short = [_spline([(x, y, _height(x, y)) for y in np.linspace(0, 3, 7)]) for x in (0, 1, 2.5, 3.5)]
    with pytest.raises(sm.SurfmodError, match=r"profiles\[\d\]: its ends must lie on the first and last guides"):
        sm.gordon(profiles, short, 1e-3)


def test_rational_profiles_are_reparametrized_within_tolerance():
    import build123d as bd

    profiles = [bd.Edge.make_three_point_arc((0, y, 0), (5, y, 2 + 0.2 * y), (10, y, 0)) for y in (0, 5, 10)]
    guides = [sm.Line((0, 0, 0), (0, 10, 0)), sm.Line((10, 0, 0), (10, 10, 0)),
              _spline([(5, y, 2 + 0.2 * y) for y in (0, 5, 10)])]
    s = sm.gordon(profiles, guides, 1e-4)
    assert s.reparametrized and not s.rational
    assert s.network_deviation() <= 1e-4
