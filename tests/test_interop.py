"""Round trips through geomdl, splipy and rhino3dm: degrees, knots and weights identical,
nets identical (polynomial) or equal to the last bit of the homogeneous quotient
(rational), and each library's own evaluation equal to ours to 1e-13."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from hypothesis import given, settings
from strategies import bspline_surfaces, parameters_with_knots

import surfmod as sm

LIBS = ["geomdl", "splipy", "rhino3dm"]
CONVERT = {
    "geomdl": (lambda o: sm.to_geomdl(o), lambda o: sm.from_geomdl(o)),
    "splipy": (lambda o: sm.to_splipy(o), lambda o: sm.from_splipy(o)),
    "rhino3dm": (lambda o: sm.to_rhino(o), lambda o: sm.from_rhino(o)),
}


def _surface(seed, rational):
    rng = np.random.default_rng(seed)
    p, q = int(rng.integers(1, 5)), int(rng.integers(1, 5))
    n, m = p + 1 + int(rng.integers(0, 4)), q + 1 + int(rng.integers(0, 4))
    net = rng.normal(0, 3, (n, m, 3))

    def knots(deg, cnt):
        inner = np.sort(rng.random(cnt - deg - 1))
        if inner.size >= 2 and deg >= 2:
            inner[1] = inner[0]  # a double knot
        return np.concatenate([np.zeros(deg + 1), inner, np.ones(deg + 1)]) * 2.5 - 0.7

    w = rng.uniform(0.2, 4.0, (n, m)) if rational else None
    return sm.BSplineSurface(net, (p, q), (knots(p, n), knots(q, m)), w)


def _curve(seed, rational):
    s = _surface(seed, rational)
    return sm.BSplineCurve(s.control_points[:, 0], s.degree[0], s.knots[0], None if s.weights is None else s.weights[:, 0])


def _their_points(lib, obj, uv):
    if lib == "geomdl":
        if hasattr(obj, "degree_u"):
            return np.array(obj.evaluate_list([tuple(x) for x in uv]))
        return np.array(obj.evaluate_list(list(uv)))
    if lib == "splipy":
        if uv.ndim == 2:
            return obj(uv[:, 0], uv[:, 1], tensor=False)
        return obj(uv)
    if uv.ndim == 2:
        return np.array([[p.X, p.Y, p.Z] for p in (obj.PointAt(float(a), float(b)) for a, b in uv)])
    return np.array([[p.X, p.Y, p.Z] for p in (obj.PointAt(float(a)) for a in uv)])


def _assert_same(a, b):
    assert a.degree == b.degree
    for ka, kb in zip(np.atleast_2d(a.knots) if a.knots[0].ndim == 0 else a.knots,
                      np.atleast_2d(b.knots) if b.knots[0].ndim == 0 else b.knots):
        assert np.array_equal(ka, kb)
    if a.weights is None:
        assert b.weights is None
        assert np.array_equal(a.control_points, b.control_points)
    else:
        assert np.array_equal(a.weights, b.weights)
        np.testing.assert_allclose(b.control_points, a.control_points, rtol=2.3e-16, atol=1e-300)


@pytest.mark.parametrize("lib", LIBS)
@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("seed", range(5))
def test_surface_round_trip_and_their_evaluation(lib, rational, seed):
    pytest.importorskip(lib)
    s = _surface(seed, rational)
    to, back = CONVERT[lib]
    theirs = to(s)
    _assert_same(s, back(theirs))
    (u0, u1), (v0, v1) = s.domain
    rng = np.random.default_rng(seed)
    uv = np.column_stack([u0 + rng.random(40) * (u1 - u0), v0 + rng.random(40) * (v1 - v0)])
    ours = s.points(uv[:, 0], uv[:, 1])
    assert np.abs(_their_points(lib, theirs, uv) - ours).max() <= 1e-13 * max(1.0, np.abs(ours).max())


@pytest.mark.parametrize("lib", LIBS)
@pytest.mark.parametrize("rational", [False, True])
def test_curve_round_trip_and_their_evaluation(lib, rational):
    pytest.importorskip(lib)
    c = _curve(11, rational)
    to, back = CONVERT[lib]
    theirs = to(c)
    b = back(theirs)
    assert b.degree == c.degree and np.array_equal(b.knots, c.knots)
    if rational:
        assert np.array_equal(b.weights, c.weights)
        np.testing.assert_allclose(b.control_points, c.control_points, rtol=2.3e-16, atol=1e-300)
    else:
        assert np.array_equal(b.control_points, c.control_points)
    t = np.linspace(*c.domain, 23)
    assert np.abs(_their_points(lib, theirs, t) - c.points(t)).max() <= 1e-13 * max(1.0, np.abs(c.control_points).max())


@pytest.mark.parametrize("lib", LIBS)
def test_rational_ellipsoid_keeps_its_weights(lib):
    # cadquery's Surface.fromFace drops the weights here (a 4.0 position error)
    pytest.importorskip(lib)
    e = sm.ellipsoid(5.0, 3.0, 2.0)
    to, back = CONVERT[lib]
    b = back(to(e))
    (u0, u1), (v0, v1) = e.domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, 17), np.linspace(v0, v1, 11))
    p = b.points(uu, vv)
    np.testing.assert_allclose((p[..., 0] / 5) ** 2 + (p[..., 1] / 3) ** 2 + (p[..., 2] / 2) ** 2, 1.0, atol=1e-14)
    assert np.abs(p - e.points(uu, vv)).max() <= 1e-14


def test_3dm_file_round_trip(tmp_path):
    pytest.importorskip("rhino3dm")
    s, c = _surface(3, True), _curve(4, False)
    path = tmp_path / "net.3dm"
    sm.to_rhino([s, c], path)
    back = sm.from_rhino(path)
    assert len(back) == 2
    _assert_same(s, back[0])
    assert np.array_equal(back[1].control_points, c.control_points) and np.array_equal(back[1].knots, c.knots)


def test_rhino_unclamped_knots_give_the_same_spline():
    pytest.importorskip("rhino3dm")
    net = np.random.default_rng(5).normal(0, 1, (6, 5, 3))
    s = sm.BSplineSurface.uniform_cubic(net)
    b = sm.from_rhino(sm.to_rhino(s))
    assert np.array_equal(b.knots[0][1:-1], s.knots[0][1:-1])
    uu, vv = np.meshgrid(np.linspace(*s.domain[0], 9), np.linspace(*s.domain[1], 7))
    assert np.abs(b.points(uu, vv) - s.points(uu, vv)).max() <= 1e-14


def test_analytic_surfaces_and_build123d_faces_are_converted():
    pytest.importorskip("geomdl")
    import build123d as bd

    g = sm.to_geomdl(sm.sphere(2.0))
    p = np.array(g.evaluate_list([(0.3, 0.2), (0.9, 0.7)]))
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 2.0, atol=1e-13)
    face = bd.Face.make_rect(2, 3)
    b = sm.from_geomdl(sm.to_geomdl(face))
    assert b.degree == (1, 1)


@pytest.mark.parametrize("lib,call", [("geomdl", "to_geomdl"), ("splipy", "to_splipy"), ("rhino3dm", "to_rhino"),
                                      ("geomdl", "from_geomdl"), ("splipy", "from_splipy"), ("rhino3dm", "from_rhino")])
def test_missing_library_names_the_extra(lib, call, monkeypatch):
    monkeypatch.setitem(sys.modules, lib, None)  # import now raises ImportError
    with pytest.raises(sm.MissingExtraError, match=rf"{call} needs the optional package '{lib}': pip install \"surfmod\[interop\]\""):
        getattr(sm, call)(sm.BSplineCurve([(0, 0, 0), (1, 0, 0)], 1))


def test_bad_input_is_named():
    with pytest.raises(sm.SurfmodError, match="obj: expected a surfmod surface or curve"):
        sm.to_geomdl("not a surface")
    with pytest.raises(sm.SurfmodError, match="obj: expected a geomdl curve or surface"):
        sm.from_geomdl(42)
    with pytest.raises(sm.SurfmodError, match="obj: expected a splipy Curve or Surface"):
        sm.from_splipy([1, 2])
    with pytest.raises(sm.SurfmodError, match="obj: expected rhino3dm NURBS geometry"):
        sm.from_rhino(3.0)


@settings(max_examples=25, deadline=None)
@given(s=bspline_surfaces())
def test_random_surfaces_survive_every_library_and_iges(s, tmp_path_factory):
    # degrees 1-7, repeated interior knots, weights over two decades (tests/strategies.py)
    pytest.importorskip("geomdl"), pytest.importorskip("splipy"), pytest.importorskip("rhino3dm")
    us, vs = parameters_with_knots(s)
    uu, vv = np.meshgrid(us, vs)
    ref = s.points(uu, vv)
    for lib in LIBS:
        to, back = CONVERT[lib]
        b = back(to(s))
        _assert_same(s, b)
        assert np.abs(b.points(uu, vv) - ref).max() <= 1e-13 * max(1.0, np.abs(ref).max())
    path = tmp_path_factory.mktemp("iges") / "s.igs"
    sm.export_iges(s, path)
    b = sm.from_face(sm.import_iges(path).faces()[0])
    assert np.abs(b.points(uu, vv) - ref).max() <= 1e-13 * max(1.0, np.abs(ref).max())
