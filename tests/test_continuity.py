"""sm.continuity: closed forms, C2 splits, OCCT's LocalAnalysis at the same points, shells."""

import numpy as np
import pytest

import surfmod as sm


def wavy_spline(seed=1):
    rng = np.random.default_rng(seed)
    net = np.zeros((7, 6, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:7, 0:6]
    net[..., 2] = rng.normal(size=(7, 6))
    return sm.BSplineSurface(net, (3, 3), ([0, 0, 0, 0, .3, .5, .7, 1, 1, 1, 1], [0, 0, 0, 0, .4, .6, 1, 1, 1, 1]))


@pytest.mark.parametrize("radius", [0.5, 2.0, 7.0])
def test_plane_tangent_to_cylinder_jumps_by_one_over_r(radius):
    cyl = sm.CylindricalSurface(radius, u_range=(0, 1.2), v_range=(0, 3))
    flat = sm.plane((radius, 0, 0), (radius, 0, 3), (radius, -2, 0))
    c = sm.continuity(cyl, flat, samples=21, occt=True)
    assert c.label == "a.u0 | b.v0"
    assert c.g0 < 1e-14 and c.g1 < 1e-14
    np.testing.assert_allclose(c.jump, 1.0 / radius, rtol=1e-13)
    np.testing.assert_allclose(np.abs(c.curvature_a), 1.0 / radius, rtol=1e-13)
    np.testing.assert_allclose(c.curvature_b, 0.0, atol=1e-15)
    assert c.level() == "G1"
    # OCCT's gap mixes mean and half-difference curvature: 1/(2R) for this pair
    np.testing.assert_allclose(c.occt[:, 2], 0.5 / radius, rtol=1e-12)
    np.testing.assert_allclose(c.occt[:, 1], c.angle, atol=1e-14)


def test_split_at_a_simple_knot_is_c2_and_matches_occt():
    s = wavy_spline()
    a, b = s.split(u=0.5)          # 0.5 is a simple knot of a cubic: C2 across
    c = sm.continuity(a, b, samples=40, occt=True)
    assert (c.g0, c.g1) < (1e-13, 1e-13)
    assert c.g2 < 1e-12 and c.g2_relative < 1e-13
    assert c.level() == "G2"
    np.testing.assert_allclose(c.occt[:, 0], c.gap, atol=1e-13)
    np.testing.assert_allclose(c.occt[:, 1], c.angle, atol=1e-13)
    assert np.nanmax(c.occt[:, 2]) < 1e-12
    # the curvature across equals the full surface's, evaluated independently
    n = s.normals(0.5, c.params_a[:, 1])
    assert np.allclose(np.abs(c.curvature_a), np.abs(c.curvature_b), atol=1e-12)
    assert n.shape == (40, 3)


def test_split_off_the_knots_in_v_and_reversed_orientation():
    s = wavy_spline(3)
    a, b = s.split(v=0.3)
    flipped = sm.BSplineSurface(b.control_points[::-1], b.degree, (1 - b.knots[0][::-1], b.knots[1]))
    c = sm.continuity(flipped, a)
    assert c.label == "a.v0 | b.v1"
    assert c.g0 < 1e-13 and c.g1 < 1e-12 and c.g2_relative < 1e-11
    # the boundary runs backwards on b: corresponding u are mirrored
    np.testing.assert_allclose(c.params_b[:, 0], 1 - c.params_a[:, 0], atol=1e-12)


def test_crease_angle_and_fold():
    a = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    up = sm.plane((0, 1, 0), (1, 1, 0), (0, 1 + np.cos(1.0), np.sin(1.0)))
    c = sm.continuity(a, up)
    np.testing.assert_allclose(c.angle, 1.0, rtol=1e-13)
    assert c.level() == "G0"
    fold = sm.plane((0, 1, 0), (1, 1, 0), (0, 0, 0.0))   # doubles back over a
    assert sm.continuity(a, fold, edge=("v1", "u0")).g1 == pytest.approx(np.pi, rel=1e-12)


def test_given_edge_and_gap():
    a = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    b = sm.plane((0, 1, 0.01), (1, 1, 0.01), (0, 2, 0.01))
    c = sm.continuity(a, b, edge=("v1", "v0"))
    np.testing.assert_allclose(c.gap, 0.01, rtol=1e-12)
    assert c.level() == "none"
    with pytest.raises(sm.SurfmodError, match="edge"):
        sm.continuity(a, b, edge=("x", "v0"))
    with pytest.raises(sm.SurfmodError, match="b: no side"):
        sm.continuity(a, b.translated((0, 5, 0)))
    with pytest.raises(sm.SurfmodError, match="samples"):
        sm.continuity(a, b, samples=0)
    with pytest.raises(sm.SurfmodError, match="a:"):
        sm.continuity(a)


def test_shell_box_and_cylinder():
    import build123d as bd

    box = sm.continuity(bd.Box(1, 2, 3), samples=9)
    assert len(box.edges) == 12
    np.testing.assert_allclose([e.g1 for e in box.edges], np.pi / 2, rtol=1e-13)
    assert box.g0 < 1e-12
    cyl = sm.continuity(bd.Cylinder(1.5, 2), samples=9, occt=True)
    assert len(cyl.edges) == 2        # the seam is not an edge between two faces
    np.testing.assert_allclose(cyl.g1, np.pi / 2, rtol=1e-12)
    # cap (plane) against the side (cylinder): across the circular edge the side is straight
    np.testing.assert_allclose(cyl.jump, 0.0, atol=1e-12)
    assert "edge" in str(cyl) and "max over 2 edges" in str(cyl)


def test_faces_sharing_an_edge_through_pcurves():
    import build123d as bd

    faces = bd.Box(1, 1, 1).faces()
    c = sm.continuity(faces[0], faces[2])
    assert c.label == "face a | face b"
    np.testing.assert_allclose(c.angle, np.pi / 2, rtol=1e-13)


def test_tangent_fillet_on_a_real_solid_is_g1_with_known_jump():
    import build123d as bd

    part = bd.fillet(bd.Box(4, 4, 4).edges().group_by(bd.Axis.Z)[-1], 0.5)
    c = sm.continuity(part, samples=11, occt=True)
    smooth = [e for e in c.edges if e.g1 < 1e-6]
    assert smooth, "the fillet meets its neighbours tangentially"
    jumps = np.concatenate([e.jump for e in smooth])
    # plane | cylinder fillet: 1/R = 2; sphere-like corner blends are not in a box fillet
    assert np.isclose(jumps.max(), 2.0, rtol=1e-6)
    occt_g1 = np.concatenate([e.occt[:, 1] for e in smooth])
    assert np.nanmax(occt_g1) < 1e-6


def _check_against_occt(path):
    shape = sm.import_step(path)
    c = sm.continuity(shape, samples=5, occt=True)
    if not c.edges:
        return 0
    ok = np.all(np.isfinite(c.occt[:, :2]), axis=1)
    size = np.ptp(c.points, axis=0).max()
    np.testing.assert_allclose(c.gap[ok], c.occt[ok, 0], atol=1e-9 * max(size, 1.0))
    folded = np.minimum(c.angle, np.pi - c.angle)          # OCCT folds the angle into [0, pi/2]
    np.testing.assert_allclose(folded[ok], c.occt[ok, 1], atol=1e-7)
    return len(c.edges)


def test_one_corpus_file_against_occt(corpus_dir):
    path = corpus_dir / "cadquery_red_cube_blue_cylinder.step"
    assert _check_against_occt(path) > 0


@pytest.mark.corpus
def test_corpus_continuity_against_occt(judged_file):
    _check_against_occt(judged_file)
