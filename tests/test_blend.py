"""sm.blend: exact G0/G1/G2 B-spline blends, verified with sm.continuity and OCCT's
LocalAnalysis_SurfaceContinuity, and OCCT's MakeFilling on the same case."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.ops.blend import occt_blend


def patch(seed, shift=(0.0, 0.0, 0.0), degree=(3, 3), knots=None, weights=False, shape=(6, 5)):
    rng = np.random.default_rng(seed)
    net = np.zeros(shape + (3,))
    net[..., 0], net[..., 1] = np.mgrid[0:shape[0], 0:shape[1]]
    net[..., 2] = 0.3 * rng.normal(size=shape)
    net += shift
    w = 1 + 0.5 * rng.random(shape) if weights else None
    return sm.BSplineSurface(net, degree, knots, w)


@pytest.fixture
def pair():
    a = patch(2, degree=(3, 2), knots=([0, 0, 0, 0, .4, .7, 1, 1, 1, 1], [0, 0, 0, .5, .7, 1, 1, 1]), weights=True)
    b = patch(5, shift=(8.0, 0.5, 1.0), shape=(5, 7))
    return a, b


def check_join(x, y, g1_tol, g2_rel_tol):
    c = sm.continuity(x, y, samples=60, occt=True)
    assert c.g0 < 1e-12
    assert c.g1 <= g1_tol
    assert np.nanmax(c.occt[:, 0]) < 1e-12 and np.nanmax(c.occt[:, 1]) <= g1_tol
    if g2_rel_tol is not None:
        length = np.linalg.norm(np.diff(c.points, axis=0), axis=1).sum()
        scale = max(np.abs(c.curvature_a).max(), np.abs(c.curvature_b).max(), 1 / length)
        assert c.g2_relative <= g2_rel_tol
        assert np.nanmax(c.occt[:, 2]) <= g2_rel_tol * scale
    return c


def test_g2_blend_between_nurbs_and_bspline(pair):
    a, b = pair
    f = sm.blend(a, "u1", b, "u0", "G2")
    assert f.degree[1] == 5 and f.rational
    check_join(a, f, 1e-12, 1e-10)
    check_join(f, b, 1e-12, 1e-10)
    assert sm.crosscheck(f).passed


def test_g1_blend_is_cubic_and_g1_but_not_g2(pair):
    a, b = pair
    f = sm.blend(a, "u1", b, "u0", "G1")
    assert f.degree[1] == 3
    c = check_join(a, f, 1e-12, None)
    assert c.level() == "G1" and c.g2_relative > 1e-3


def test_g0_blend_is_ruled_between_the_boundaries(pair):
    a, b = pair
    f = sm.blend(a, "u1", b, "u0", "G0")
    assert f.degree[1] == 1
    c = sm.continuity(a, f)
    assert c.g0 < 1e-12 and c.g1 > 1e-3


def test_boundary_rows_are_the_neighbours_sides_exactly(pair):
    a, b = pair
    f = sm.blend(a, "v0", b, "u1", "G2")     # any sides, orientation found
    t = np.linspace(0, 1, 17)
    edge_f = f.points(t, 0.0)
    edge_a = a.points(t, 0.0)
    assert np.allclose(edge_f, edge_a, atol=1e-13) or np.allclose(edge_f, edge_a[::-1], atol=1e-13)
    far = f.points(t, 1.0)
    edge_b = b.points(1.0, t)
    assert np.allclose(far, edge_b, atol=1e-13) or np.allclose(far, edge_b[::-1], atol=1e-13)
    check_join(a, f, 1e-12, 1e-10)
    check_join(f, b, 1e-12, 1e-10)
    # oriented like a: normals agree along the shared side
    pa = sm.project(edge_f[8:9], a)
    assert np.dot(f.normals(0.5, 0.0), a.normals(pa.u[0], pa.v[0])) > 0.999


def test_tension_scales_the_cross_tangent_exactly():
    a, b = patch(1), patch(3, shift=(8.0, 0.0, 1.0))
    f1 = sm.blend(a, "u1", b, "u0", "G1", tension=1.0)
    f2 = sm.blend(a, "u1", b, "u0", "G1", tension=(2.5, 1.0))
    leg1 = f1.control_points[:, 1] - f1.control_points[:, 0]
    leg2 = f2.control_points[:, 1] - f2.control_points[:, 0]
    np.testing.assert_allclose(leg2, 2.5 * leg1, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(f2.control_points[:, 2], f1.control_points[:, 2], atol=1e-13)
    check_join(a, f2, 1e-12, None)


def test_blend_to_an_analytic_cylinder_is_g2():
    cyl = sm.CylindricalSurface(3.0, (0, 0, 0), (0, 0, 1), u_range=(0, 1.0), v_range=(0, 4))
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 2] = np.mgrid[6:9:4j, 0:4:4j]
    net[..., 1] = 4.0
    flat = sm.BSplineSurface(net)
    f = sm.blend(cyl, "u1", flat, "u0", "G2")
    c = sm.continuity(cyl, f, occt=True)
    assert c.g1 < 1e-12 and c.g2_relative < 1e-9
    np.testing.assert_allclose(np.abs(c.curvature_a), 1 / 3.0, rtol=1e-12)
    check_join(f, flat, 1e-12, 1e-10)


def test_bad_input_is_named(pair):
    a, b = pair
    with pytest.raises(sm.SurfmodError, match="side_a"):
        sm.blend(a, "w0", b, "u0")
    with pytest.raises(sm.SurfmodError, match="continuity"):
        sm.blend(a, "u1", b, "u0", "G3")
    with pytest.raises(sm.SurfmodError, match="tension"):
        sm.blend(a, "u1", b, "u0", tension=-1)
    with pytest.raises(sm.SurfmodError, match="b:"):
        sm.blend(a, "u1", "not a surface", "u0")
    with pytest.raises(sm.SurfmodError, match="coincide"):
        sm.blend(a, "u1", a, "u1")


def test_occt_filling_on_the_same_case_stays_short_of_g1_and_refuses_g2(pair):
    a, b = patch(2), patch(5, shift=(8.0, 0.5, 1.0), shape=(5, 7))
    ours = sm.blend(a, "u1", b, "u0", "G2")
    face, fa, fb = occt_blend(a, "u1", b, "u0", ours, "G1")
    theirs = sm.continuity(a, face, occt=True)
    mine = sm.continuity(a, ours, occt=True)
    assert theirs.g1 > 1e-4 > 1e-12 > mine.g1          # a visible normal jump for OCCT's plate
    np.testing.assert_allclose(theirs.occt[:, 1], theirs.angle, atol=1e-9)
    with pytest.raises(sm.KernelError, match="continuity"):
        occt_blend(a, "u1", b, "u0", ours, "G2")


def test_faces_are_accepted(pair):
    a, b = pair
    f = sm.blend(a.face(), "u1", b.face(), "u0", "G2")
    check_join(a, f, 1e-12, 1e-10)
