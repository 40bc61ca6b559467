"""Transforms through the control points vs OCCT's gp_Trsf / gp_GTrsf applied to geom()."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import surfmod as sm
from strategies import bspline_surfaces
from surfmod import transforms
from twins.transformed import geom_gtransformed, geom_transformed, named_trsf, trsf_matrix
from surfmod.occ.geom import surface_type
from surfmod.occ.sample import curve_d2, surface_d0


def _net(n, m, seed=0):
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(0, 4, n), np.linspace(0, 3, m), indexing="ij")
    return np.stack([x, y, rng.uniform(-1, 1, (n, m))], axis=-1)


def _hermite():
    rng = np.random.default_rng(7)
    c = np.zeros((2, 2, 3))
    c[1, :, 0] = 2.0
    c[:, 1, 1] = 1.5
    c[..., 2] = rng.uniform(-0.5, 0.5, (2, 2))
    return sm.HermiteBicubic(c, rng.uniform(-1, 1, (2, 2, 3)), rng.uniform(-1, 1, (2, 2, 3)), rng.uniform(-1, 1, (2, 2, 3)))


SUBJECTS = {
    "bspline": lambda: sm.BSplineSurface(_net(6, 5), (3, 2), ([0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1], [0, 0, 0, 0.5, 0.5, 1, 1, 1])),
    "nurbs": lambda: sm.BSplineSurface(_net(5, 5, 1), (2, 3), None, 0.5 + np.random.default_rng(3).uniform(0, 2, (5, 5))),
    "uniform_cubic": lambda: sm.BSplineSurface.uniform_cubic(_net(6, 6, 2)),
    "bezier": lambda: sm.BezierSurface(_net(4, 5, 4)),
    "bezier_rational": lambda: sm.BezierSurface(_net(3, 3, 5), np.array([[1, 2, 1], [0.5, 3, 1], [1, 1, 2.0]])),
    "hermite": _hermite,
    "plane": lambda: sm.plane((1, 0, 0), (3, 1, 0), (0, 2, 1)),
}

NAMED = {
    "translation": (lambda s: s.translated((1.5, -2.0, 0.25)), ("translation", (1.5, -2.0, 0.25))),
    "rotation": (lambda s: s.rotated((1, 2, 3), (1, -1, 2), 37.0), ("rotation", (1, 2, 3), np.array([1, -1, 2]) / 6**0.5, 37.0)),
    "mirror": (lambda s: s.mirrored((0.5, 0, 1), (1, 2, -1)), ("mirror", (0.5, 0, 1), np.array([1, 2, -1]) / 6**0.5)),
    "scale": (lambda s: s.scaled(2.5, (1, 1, 0)), ("scale", (1, 1, 0), 2.5)),
    "scale_negative": (lambda s: s.scaled(-0.75, (0, 1, 2)), ("scale", (0, 1, 2), -0.75)),
}


def _params(s, count=9):
    (u0, u1), (v0, v1) = s.domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, count), np.linspace(v0, v1, count), indexing="ij")
    return uu.ravel(), vv.ravel()


def _assert_same_surface(mine, occ_surf, ref_scale):
    u, v = _params(mine)
    np.testing.assert_allclose(mine.points(u, v), surface_d0(occ_surf, u, v), rtol=0, atol=1e-12 * ref_scale)


def _size(s):
    return max(1.0, float(np.abs(s.control_points).max()))


@pytest.mark.parametrize("subject", sorted(SUBJECTS))
@pytest.mark.parametrize("kind", sorted(NAMED))
def test_named_transforms_match_gp_trsf(subject, kind):
    s = SUBJECTS[subject]()
    apply, trsf_args = NAMED[kind]
    mine = apply(s)
    assert type(mine) is type(s)  # Hermite stays Hermite, Bezier stays Bezier
    theirs = geom_transformed(s.geom(), named_trsf(*trsf_args))
    assert surface_type(theirs) == surface_type(s.geom())
    _assert_same_surface(mine, theirs, 10 * _size(mine))
    # the geom() of the transformed surface is the transformed geom
    _assert_same_surface(mine, mine.geom(), 10 * _size(mine))


@pytest.mark.parametrize("kind", sorted(NAMED))
def test_named_matrices_equal_gp_trsf_matrices(kind):
    """surfmod's 4x4 matrices equal the matrices OCCT builds with its own setters."""
    s = SUBJECTS["bspline"]()
    apply, trsf_args = NAMED[kind]
    captured = {}

    class Spy(sm.BSplineSurface):
        def transformed(self, matrix):
            captured["m"] = np.asarray(matrix)
            return self

    spy = Spy.__new__(Spy)
    sm.BSplineSurface._set(spy, s.control_points, s.degree, s.knots, s.weights)
    apply(spy)
    np.testing.assert_allclose(captured["m"], trsf_matrix(named_trsf(*trsf_args)), rtol=0, atol=1e-15 * 8)


@pytest.mark.parametrize("subject", sorted(SUBJECTS))
def test_nonuniform_scale_matches_gp_gtrsf(subject):
    s = SUBJECTS[subject]()
    factor, center = np.array([2.0, 0.5, -3.0]), np.array([1.0, -1.0, 0.5])
    mine = s.scaled(factor, center)
    assert type(mine) is type(s)
    m = np.eye(4)
    m[:3, :3] = np.diag(factor)
    m[:3, 3] = center * (1 - factor)
    theirs = geom_gtransformed(s.geom(), m)
    _assert_same_surface(mine, theirs, 10 * _size(mine))
    # and the point images: S'(u, v) = M S(u, v) (affine invariance of rational splines)
    u, v = _params(s)
    np.testing.assert_allclose(mine.points(u, v), s.points(u, v) * factor + center * (1 - factor), atol=1e-12 * _size(mine))


def test_hermite_data_map_affinely():
    h = _hermite()
    m = transforms.rotation_matrix((0, 0, 1), (1, 1, 1), 50.0) @ transforms.scale_matrix((1, 2, 3))
    t = h.transformed(m)
    assert isinstance(t, sm.HermiteBicubic)
    np.testing.assert_allclose(t.corners, transforms.apply(m, h.corners), atol=1e-14)
    np.testing.assert_allclose(t.du, h.du @ m[:3, :3].T, atol=1e-14)
    np.testing.assert_allclose(t.twist, h.twist @ m[:3, :3].T, atol=1e-14)
    # derivatives transform linearly: the corner tangents of the new patch are the data
    d = t.derivatives(np.array([0.0, 1.0]), np.array([0.0, 1.0]), 1)
    np.testing.assert_allclose(d[:, 1, 0], t.du[[0, 1], [0, 1]], atol=1e-12)
    np.testing.assert_allclose(d[:, 1, 1], t.twist[[0, 1], [0, 1]], atol=1e-12)


unit = st.floats(-1, 1, allow_nan=False)
coord = st.floats(-10, 10, allow_nan=False)


@settings(max_examples=25, deadline=None)
@given(
    s=bspline_surfaces(max_degree=4),
    axis=st.tuples(unit, unit, unit).filter(lambda a: np.linalg.norm(a) > 0.1),
    origin=st.tuples(coord, coord, coord),
    degrees=st.floats(-360, 360, allow_nan=False),
    shift=st.tuples(coord, coord, coord),
    factor=st.floats(0.1, 10).map(lambda f: f) | st.floats(-10, -0.1),
)
def test_random_similarities_match_gp_trsf(s, axis, origin, degrees, shift, factor):
    axis = np.asarray(axis) / np.linalg.norm(axis)
    mine = s.rotated(origin, axis, degrees).translated(shift).mirrored(origin, axis).scaled(factor, shift)
    t = named_trsf("scale", shift, factor)
    t.Multiply(named_trsf("mirror", origin, axis))
    t.Multiply(named_trsf("translation", shift))
    t.Multiply(named_trsf("rotation", origin, axis, degrees))
    theirs = geom_transformed(s.geom(), t)
    scale = max(1.0, float(np.abs(mine.control_points).max()), 30 * abs(factor))
    _assert_same_surface(mine, theirs, 10 * scale)


@settings(max_examples=25, deadline=None)
@given(s=bspline_surfaces(max_degree=4), seed=st.integers(0, 2**31 - 1))
def test_random_affine_maps_match_gp_gtrsf(s, seed):
    rng = np.random.default_rng(seed)
    m = np.eye(4)
    m[:3, :3] = rng.uniform(-3, 3, (3, 3))
    m[:3, 3] = rng.uniform(-10, 10, 3)
    if abs(np.linalg.det(m[:3, :3])) < 1e-2:
        m[:3, :3] += 3 * np.eye(3)
    mine = s.transformed(m)
    theirs = geom_gtransformed(s.geom(), m)
    _assert_same_surface(mine, theirs, 10 * max(_size(mine), np.abs(m).max() * _size(s)))
    # the NumPy image of the points is the image of the NumPy points
    u, v = _params(s, 5)
    np.testing.assert_allclose(mine.points(u, v), transforms.apply(m, s.points(u, v)), atol=1e-11 * np.abs(m).max() * _size(s))


def test_transforms_are_new_objects_and_frozen():
    s = SUBJECTS["nurbs"]()
    t = s.translated((1, 0, 0))
    assert t is not s and not t.control_points.flags.writeable
    np.testing.assert_array_equal(t.weights, s.weights)
    np.testing.assert_array_equal(s.control_points, SUBJECTS["nurbs"]().control_points)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda s: s.transformed(np.eye(3)), "matrix"),
        (lambda s: s.transformed(np.diag([1.0, 1.0, 0.0, 1.0])), "matrix"),
        (lambda s: s.transformed(np.full((4, 4), np.nan)), "matrix"),
        (lambda s: s.transformed([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1]]), "matrix"),
        (lambda s: s.rotated((0, 0, 0), (0, 0, 0), 30), "axis_direction"),
        (lambda s: s.rotated((0, 0, np.nan), (0, 0, 1), 30), "axis_origin"),
        (lambda s: s.rotated((0, 0, 0), (0, 0, 1), np.inf), "degrees"),
        (lambda s: s.mirrored((0, 0, 0), (0, 0, 0)), "normal"),
        (lambda s: s.scaled(0.0), "factor"),
        (lambda s: s.scaled((1, 2)), "factor"),
        (lambda s: s.translated((1, 2)), "vector"),
    ],
)
def test_bad_transform_input(call, match):
    with pytest.raises(sm.SurfmodError, match=match):
        call(SUBJECTS["bspline"]())


CURVES = {
    "nurbs": lambda: sm.BSplineCurve([(0, 0, 0), (1, 2, 0.5), (3, 1, -1), (4, 3, 2)], 2, weights=[1, 2, 0.5, 1]),
    "circle": lambda: sm.Circle((1, -1, 0.5), (1, 2, 2), 1.5),
    "line": lambda: sm.Line((0, 1, 2), (3, -1, 4)),
}


@pytest.mark.parametrize("subject", sorted(CURVES))
def test_curves_share_the_named_transforms_and_match_gp_trsf(subject):
    c = CURVES[subject]()
    for apply, trsf_args in NAMED.values():
        mine = apply(c)
        t = np.linspace(*mine.domain, 11)
        theirs = curve_d2(c.geom().Transformed(named_trsf(*trsf_args)), t)[:, 0]
        np.testing.assert_allclose(mine.points(t), theirs, rtol=0, atol=1e-11)
