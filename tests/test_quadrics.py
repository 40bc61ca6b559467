"""Sphere, torus, ellipsoid and the other OCCT elementary surfaces: OCCT's frames and
parametrizations, implicit forms, textbook areas and volumes, transforms vs gp_Trsf."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from reference import enclosed_volume as volume
from reference import surface_area as area
from twins.transformed import transformed as occ_transformed
from surfmod.occ.sample import surface_d0, surface_d2
from surfmod.transforms import mirror_matrix, rotation_matrix, scale_matrix, translation_matrix


def _grid(domain, n=11, m=9):
    (u0, u1), (v0, v1) = domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, m), indexing="ij")
    return uu.ravel(), vv.ravel()


def test_sphere_points_area_volume_and_implicit():
    c, r = np.array([1.0, -2.0, 0.5]), 2.0
    s = sm.sphere(r, center=c)
    uu, vv = _grid(s.domain)
    expected = c + r * np.stack([np.cos(vv) * np.cos(uu), np.cos(vv) * np.sin(uu), np.sin(vv)], axis=1)
    np.testing.assert_allclose(s.points(uu, vv), expected, atol=1e-14)
    np.testing.assert_allclose(s.implicit(s.points(uu, vv)), 0.0, atol=1e-14)
    assert area(s) == pytest.approx(4 * math.pi * r * r, rel=1e-14)
    assert volume(s) == pytest.approx(4 / 3 * math.pi * r**3, rel=1e-14)
    assert s.face().area == pytest.approx(4 * math.pi * r * r, rel=1e-9)
    res = sm.crosscheck(s, samples=16)
    assert res.passed and res.max_deviation < 1e-13, res.details
    np.testing.assert_allclose(s.normals(0.3, 0.2), (s.points(0.3, 0.2) - c) / r, atol=1e-15)
    k = s.curvatures(0.3, 0.2)
    assert k.gaussian == pytest.approx(1 / r**2, rel=1e-13) and k.mean == pytest.approx(-1 / r, rel=1e-13)


def test_torus_area_volume_implicit():
    big, small = 3.0, 0.75
    t = sm.torus(big, small, center=(0, 0, 1), axis=(0, 1, 1))
    uu, vv = _grid(t.domain)
    np.testing.assert_allclose(t.implicit(t.points(uu, vv)), 0.0, atol=1e-12)
    assert area(t) == pytest.approx(4 * math.pi**2 * big * small, rel=1e-14)
    assert volume(t) == pytest.approx(2 * math.pi**2 * big * small**2, rel=1e-13)
    res = sm.crosscheck(t, samples=16)
    assert res.passed and res.max_deviation < 1e-13, res.details


def test_ellipsoid_is_an_exact_nurbs():
    e = sm.ellipsoid(3.0, 2.0, 1.0, center=(1, 1, 1))
    assert isinstance(e, sm.BSplineSurface) and e.rational and e.degree == (2, 2)
    assert e.control_points.shape == (9, 5, 3)
    uu, vv = _grid(e.domain, 41, 41)
    np.testing.assert_allclose(e.implicit(e.points(uu, vv)), 0.0, atol=1e-14)
    assert volume(e) == pytest.approx(4 / 3 * math.pi * 6.0, rel=1e-13) == e.volume()
    res = sm.crosscheck(e, samples=16)
    assert res.passed, res.details
    # the axis points are where they should be
    np.testing.assert_allclose(e.points(0.0, 0.0), (4, 1, 1), atol=1e-14)
    np.testing.assert_allclose(e.points(math.pi / 2, 0.0), (1, 3, 1), atol=1e-14)
    np.testing.assert_allclose(e.points(0.0, math.pi / 2), (1, 1, 2), atol=1e-14)


def test_sphere_ellipsoid_with_equal_radii_is_the_sphere():
    e = sm.ellipsoid(2.0, 2.0, 2.0)
    uu, vv = _grid(e.domain, 31, 31)
    np.testing.assert_allclose(np.linalg.norm(e.points(uu, vv), axis=1), 2.0, rtol=1e-15)


ELEMENTARY = {
    "plane": lambda: sm.PlaneSurface((1, 2, 3), (1, 1, 1), u_range=(-1, 2), v_range=(0, 3)),
    "cylinder": lambda: sm.CylindricalSurface(2.0, (1, 0, 0), (0, 1, 1), v_range=(-1, 3)),
    "cone": lambda: sm.ConicalSurface(0.3, 1.5, (1, 0, 0), (0, 1, 1), v_range=(-1, 3)),
    "sphere": lambda: sm.sphere(2.0, (1, 2, 3), (1, 2, 3)),
    "torus": lambda: sm.torus(3.0, 1.0, (1, 2, 3), (1, -2, 3)),
    "sphere_patch": lambda: sm.SphericalSurface(1.5, u_range=(0.5, 2.0), v_range=(-0.3, 1.2)),
}


@pytest.mark.parametrize("name", sorted(ELEMENTARY))
def test_elementary_matches_occt_to_second_derivatives(name):
    s = ELEMENTARY[name]()
    uu, vv = _grid(s.domain)
    mine = s.derivatives(uu, vv, 2)
    occ = surface_d2(s.geom(), uu, vv)
    idx = ([0, 1, 0, 2, 1, 0], [0, 0, 1, 0, 1, 2])
    np.testing.assert_allclose(mine[:, idx[0], idx[1]], occ[:, idx[0], idx[1]], atol=1e-13 * 5)
    np.testing.assert_allclose(s.implicit(s.points(uu, vv)), 0.0, atol=1e-12)
    res = sm.crosscheck(s, samples=12)
    assert res.passed, res.details


@pytest.mark.parametrize("name", sorted(ELEMENTARY))
def test_to_nurbs_is_the_same_surface(name):
    s = ELEMENTARY[name]()
    n = s.to_nurbs()
    assert sm.crosscheck(n, samples=12).passed
    uu, vv = _grid(n.domain, 15, 15)
    np.testing.assert_allclose(s.implicit(n.points(uu, vv)), 0.0, atol=1e-12)
    # same corners / boundary
    (u0, u1), (v0, v1) = s.domain
    np.testing.assert_allclose(n.points(u0, v0), s.points(u0, v0), atol=1e-13)
    np.testing.assert_allclose(n.points(u1, v1), s.points(u1, v1), atol=1e-13)
    assert area(n) == pytest.approx(area(s), rel=1e-11)


TRANSFORMS = {
    "rigid": rotation_matrix((1, 2, 3), (1, 1, 0), 37) @ translation_matrix((1, -2, 0.5)),
    "mirror": mirror_matrix((1, 0, 0), (1, 2, 3)),
    "scale": scale_matrix(2.5, (1, 1, 1)),
    "point_mirror": scale_matrix(-1.5, (0, 1, 0)),
}


@pytest.mark.parametrize("tname", sorted(TRANSFORMS))
@pytest.mark.parametrize("name", sorted(ELEMENTARY))
def test_similarity_keeps_the_type_and_matches_gp_trsf(name, tname):
    s, m = ELEMENTARY[name](), TRANSFORMS[tname]
    t = s.transformed(m)
    assert type(t) is type(s)
    uu, vv = _grid(t.domain, 6, 6)
    np.testing.assert_allclose(t.points(uu, vv), surface_d0(occ_transformed(s.geom(), m), uu, vv), atol=1e-13 * 5)
    su, sv = _grid(s.domain, 6, 6)
    np.testing.assert_allclose(t.points(uu, vv), s.points(su, sv) @ m[:3, :3].T + m[:3, 3], atol=1e-13 * 5)


def test_non_uniform_scale_of_a_sphere_is_an_ellipsoid():
    t = sm.sphere(2.0).scaled((1.0, 2.0, 3.0))
    assert isinstance(t, sm.BSplineSurface)
    p = t.points(*_grid(t.domain, 31, 31))
    np.testing.assert_allclose((p[:, 0] / 2) ** 2 + (p[:, 1] / 4) ** 2 + (p[:, 2] / 6) ** 2, 1.0, atol=1e-14)
    assert sm.crosscheck(t, samples=16).passed


def test_default_frame_follows_gp_ax2():
    from twins.transformed import default_x_dir

    for axis in [(1, 2, 3), (0, 1, 0), (-1, -1, 0.5)]:
        s = sm.sphere(1.0, axis=axis)
        np.testing.assert_allclose(s.x_dir, default_x_dir(axis), atol=1e-15)
        np.testing.assert_allclose(np.cross(s.z_dir, s.x_dir), s.y_dir, atol=1e-15)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sm.sphere(0.0), "radius"),
        (lambda: sm.sphere(-1.0), "radius"),
        (lambda: sm.sphere(1.0, axis=(0, 0, 0)), "axis"),
        (lambda: sm.sphere(1.0, center=(0, 0)), "center"),
        (lambda: sm.torus(1.0, 2.0), "minor"),
        (lambda: sm.torus(1.0, 0.0), "minor"),
        (lambda: sm.torus("big", 0.5), "major"),
        (lambda: sm.ellipsoid(1.0, 0.0, 1.0), "ry"),
        (lambda: sm.ellipsoid(1.0, 1.0, 1.0, center=(0, 0, np.nan)), "center"),
        (lambda: sm.ConicalSurface(0.0, 1.0), "semi_angle"),
        (lambda: sm.ConicalSurface(0.3, -1.0), "ref_radius"),
        (lambda: sm.CylindricalSurface(1.0, v_range=(2, 1)), "v_range"),
        (lambda: sm.SphericalSurface(1.0, v_range=(-2, 0)), "v_range"),
        (lambda: sm.PlaneSurface((0, 0, 0), (0, 0, 0)), "normal"),
        (lambda: sm.sphere(1.0).scaled((1, 0, 1)), "factor"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(sm.SurfmodError, match=name):
        call()


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_vec = st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1)


@settings(max_examples=20, deadline=None)
@given(
    kind=st.sampled_from(["cylinder", "cone", "sphere", "torus", "plane"]),
    center=st.tuples(*[st.floats(-10, 10, allow_nan=False)] * 3),
    axis=_vec,
    xref=_vec,
    r=st.floats(0.5, 5.0),
    mirror=st.booleans(),
)
def test_random_frames_match_occt(kind, center, axis, xref, r, mirror):
    if np.linalg.norm(np.cross(axis, xref)) < 0.05 * np.linalg.norm(axis) * np.linalg.norm(xref):
        xref = None
    s = {
        "cylinder": lambda: sm.CylindricalSurface(r, center, axis, xref, v_range=(-1, 2)),
        "cone": lambda: sm.ConicalSurface(-0.4, r, center, axis, xref, v_range=(-0.5, 2)),
        "sphere": lambda: sm.SphericalSurface(r, center, axis, xref),
        "torus": lambda: sm.ToroidalSurface(r + 1.0, r * 0.5, center, axis, xref),
        "plane": lambda: sm.PlaneSurface(center, axis, xref, u_range=(-r, r), v_range=(0, r)),
    }[kind]()
    if mirror:  # an indirect frame
        s = s.mirrored(center, xref if xref is not None else (1, 0, 0))
    uu, vv = _grid(s.domain, 6, 6)
    idx = ([0, 1, 0, 2, 1, 0], [0, 0, 1, 0, 1, 2])
    mine = s.derivatives(uu, vv, 2)[:, idx[0], idx[1]]
    occ = surface_d2(s.geom(), uu, vv)[:, idx[0], idx[1]]
    np.testing.assert_allclose(mine, occ, atol=1e-13 * max(1.0, np.abs(mine).max()))
    np.testing.assert_allclose(s.implicit(s.points(uu, vv)), 0.0, atol=1e-11 * max(1.0, r) ** 4)
