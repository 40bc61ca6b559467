"""Closest points on planes, cylinders, cones, spheres and tori in closed form, against
textbook distances, OCCT's ``GeomAPI_ProjectPointOnSurf`` (orthogonal feet) and
``BRepExtrema_DistShapeShape`` (the bounded patch, its edges and corners included)."""

from __future__ import annotations

import math

import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.construct.elementary_closest import closest_angle
from twins.geomapi import face_distances, project_points

FULL = {
    "plane": sm.PlaneSurface((1, 2, 3), (0.3, 0.2, 1), u_range=(-2, 3), v_range=(-1, 2)),
    "cylinder": sm.CylindricalSurface(2.0, (1, 0, 0), (0.2, 0.3, 1), v_range=(-1, 3)),
    "cone": sm.ConicalSurface(math.radians(30), 1.0, (0, 0, 0), (0, 0.2, 1), v_range=(-4, 3)),
    "sphere": sm.sphere(2.0, center=(1, 0, 0), axis=(1, 1, 0)),
    "torus": sm.torus(3.0, 1.0, (0, 1, 0), (1, 0, 1)),
}
PATCHES = {
    "sphere": sm.SphericalSurface(2.0, u_range=(0.5, 2.0), v_range=(-0.3, 0.9)),
    "torus": sm.ToroidalSurface(3.0, 1.0, u_range=(1, 2.5), v_range=(4, 7)),
    "cone": sm.ConicalSurface(-0.4, 1.0, u_range=(2, 4), v_range=(-5, 1)),  # both nappes
    "cylinder": sm.CylindricalSurface(2.0, u_range=(5, 8), v_range=(0, 1)),  # across u = 2 pi
    "plane": sm.PlaneSurface((0, 0, 1), (0, 0, 1), u_range=(0, 2), v_range=(0, 1)),
}


def _points(n, seed, half=6.0):
    return np.random.default_rng(seed).uniform(-half, half, (n, 3))


def _bounds(s):
    (u0, u1), (v0, v1) = s.domain
    return u0, u1, v0, v1


@pytest.mark.parametrize("name", sorted(FULL))
def test_never_farther_than_occt_and_same_feet(name):
    s = FULL[name]
    pts = _points(2000, 1)
    pr = sm.project(pts, s)
    theirs = project_points(s.geom(), _bounds(s), pts)
    found = np.isfinite(theirs[:, 2])
    assert found.sum() > 150
    diff = pr.distance[found] - theirs[found, 2]
    assert diff.max() <= 1e-12 * 6  # never farther than OCCT
    # where OCCT's foot is ours, the parameters are the same (the distance differs by round-off)
    same = np.abs(diff) <= 1e-12 * 6
    p_occt = s.points(theirs[found, 0][same], theirs[found, 1][same])
    np.testing.assert_allclose(pr.point[found][same], p_occt, atol=1e-11)
    # and the answer lies on the surface at its own parameters
    np.testing.assert_allclose(s.points(pr.u, pr.v), pr.point, atol=0)


@pytest.mark.parametrize("name", sorted(PATCHES))
def test_bounded_patches_match_occt_face_distance(name):
    s = PATCHES[name]
    pts = _points(400, 2)
    pr = sm.project(pts, s)
    d = face_distances(s.face(), pts)
    np.testing.assert_allclose(pr.distance, d, atol=1e-12 * 6, rtol=0)
    (u0, u1), (v0, v1) = s.domain
    assert np.all((pr.u >= u0) & (pr.u <= u1) & (pr.v >= v0) & (pr.v <= v1))


def test_textbook_distances():
    pts = _points(5000, 3)
    c = np.array([1.0, 0.0, 0.0])
    pr = sm.project(pts, FULL["sphere"])
    np.testing.assert_allclose(pr.distance, np.abs(np.linalg.norm(pts - c, axis=1) - 2.0), atol=2e-15 * 8)
    t = sm.torus(3.0, 1.0)
    pr = sm.project(pts, t)
    rho = np.hypot(pts[:, 0], pts[:, 1])
    np.testing.assert_allclose(pr.distance, np.abs(np.hypot(rho - 3.0, pts[:, 2]) - 1.0), atol=2e-15 * 8)
    cyl = sm.CylindricalSurface(2.0, v_range=(-10, 10))
    pr = sm.project(pts, cyl)
    np.testing.assert_allclose(pr.distance, np.abs(rho - 2.0), atol=2e-15 * 8)
    # cone of half-angle a through the apex at the origin: distance |rho cos a - z sin a| on
    # the nappe the point faces (z >= -rho tan a, the line's foot is beyond the apex otherwise)
    a = math.radians(35)
    cone = sm.ConicalSurface(a, 0.0, v_range=(-20, 20))
    pr = sm.project(pts, cone)
    ref = np.minimum(np.abs(rho * math.cos(a) - pts[:, 2] * math.sin(a)),
                     np.abs(rho * math.cos(a) + pts[:, 2] * math.sin(a)))
    np.testing.assert_allclose(pr.distance, ref, atol=2e-15 * 8)


def test_points_on_the_axis_and_at_centres():
    # every point of a circle is closest: any answer at the right distance, never NaN
    cases = [
        (sm.sphere(2.0), (0, 0, 0), 2.0),
        (sm.torus(3.0, 1.0), (0, 0, 0), math.hypot(3, 0) - 1.0),
        (sm.torus(3.0, 1.0), (0, 0, 4), 5.0 - 1.0),
        (sm.torus(3.0, 1.0), (3, 0, 0), 1.0),  # on the core circle
        (sm.CylindricalSurface(2.0, v_range=(0, 1)), (0, 0, 0.5), 2.0),
        (sm.ConicalSurface(math.radians(45), 0.0, v_range=(0, 2)), (0, 0, 0), 0.0),  # the apex
        (sm.ConicalSurface(math.radians(45), 1.0, v_range=(0, 2)), (0, 0, -1.0), 0.0),  # apex (v < 0: not in box)
    ]
    for s, p, d in cases[:-1]:
        pr = sm.project([p], s)
        assert abs(pr.distance[0] - d) <= 1e-15 * 4, (s, p)
        np.testing.assert_allclose(np.linalg.norm(pr.point[0] - p), pr.distance[0], atol=1e-15)
    s, p, _ = cases[-1]  # the apex lies outside v in [0, 2]: the rim circle v = 0 is closest
    pr = sm.project([p], s)
    assert abs(pr.distance[0] - math.sqrt(2.0)) <= 1e-15 * 4 and pr.v[0] == 0.0


def test_faces_read_back_use_their_own_parameter_box():
    for solid in (bd.Sphere(2), bd.Cone(2, 1, 3), bd.Torus(3, 1), bd.Cylinder(1, 2) - bd.Box(1, 1, 3)):
        for face in solid.faces():
            f = sm.from_face(face)
            pts = _points(200, 4, 4.0)
            pr = sm.project(pts, f)
            np.testing.assert_allclose(pr.distance, face_distances(face, pts), atol=1e-12 * 4, rtol=0)


def test_indirect_frames_and_moved_copies():
    s = sm.ToroidalSurface(3.0, 1.0, u_range=(0.5, 2.0), v_range=(1.0, 5.0)).mirrored((0, 0, 0), (0, 1, 0))
    assert np.cross(s.x_dir, s.y_dir) @ s.z_dir < 0  # an indirect frame: u turns about -Z
    m = sm.SphericalSurface(1.5, u_range=(0.2, 4.0)).rotated((1, 0, 0), (0, 1, 1), 33).scaled(2.0)
    for surf in (s, m):
        pts = _points(300, 5)
        pr = sm.project(pts, surf)
        np.testing.assert_allclose(pr.distance, face_distances(surf.face(), pts), atol=1e-12 * 12, rtol=0)


def test_closest_angle_wraps_and_picks_the_nearer_end():
    assert closest_angle(np.array([2 * math.pi + 0.5]), 0.0, 1.0)[0] == pytest.approx(0.5, abs=1e-15)
    # the arc [5, 8] crosses 2 pi: 0.5 lies inside it as 0.5 + 2 pi
    assert closest_angle(np.array([0.5]), 5.0, 8.0)[0] == pytest.approx(0.5 + 2 * math.pi, abs=1e-15)
    # outside [0, 1]: 3.5 is nearer to 1 (2.5) than to 2 pi (2.78); 3.7 is nearer to 2 pi
    np.testing.assert_array_equal(closest_angle(np.array([3.5, 3.7]), 0.0, 1.0), [1.0, 0.0])


# sm.plane's parallelogram P0 + u (P1 - P0) + v (P2 - P0) with skewed, unequal edges
SKEWED = sm.plane((1, 2, 0.5), (4, 2.5, 1), (0.5, 5, 2))


def test_three_point_plane_textbook_feet_and_distances():
    pts = _points(20000, 6)
    pr = sm.project(pts, SKEWED)
    p0, p1, p2 = SKEWED.control_points[0, 0], SKEWED.control_points[1, 0], SKEWED.control_points[0, 1]
    n = np.cross(p1 - p0, p2 - p0)
    n /= np.linalg.norm(n)
    height = (pts - p0) @ n
    foot = pts - height[:, None] * n
    # the foot's coordinates in the (skewed) edge basis, by least squares: inside the square, it is the answer
    uv = np.linalg.lstsq(np.column_stack([p1 - p0, p2 - p0]), (foot - p0).T, rcond=None)[0].T
    inside = np.all((uv >= 0) & (uv <= 1), axis=1)
    assert 1000 < inside.sum() < len(pts) - 1000
    np.testing.assert_allclose(pr.distance[inside], np.abs(height[inside]), atol=1e-12 * 8, rtol=0)
    np.testing.assert_allclose(pr.point[inside], foot[inside], atol=1e-12 * 8, rtol=0)
    np.testing.assert_allclose(np.c_[pr.u, pr.v][inside], uv[inside], atol=1e-12, rtol=0)
    # outside, the closest point lies on the boundary and is no nearer than the foot
    on_side = (np.isclose(pr.u, 0, atol=0) | np.isclose(pr.u, 1, atol=0) | np.isclose(pr.v, 0, atol=0)
               | np.isclose(pr.v, 1, atol=0))
    assert on_side[~inside].all() and (pr.distance[~inside] >= np.abs(height[~inside]) - 1e-12).all()


def test_three_point_plane_matches_occt_feet_and_face_distance():
    pts = _points(3000, 7)
    pr = sm.project(pts, SKEWED)
    assert SKEWED._closest_parameters(pts) is not None  # the closed form, not the search
    theirs = project_points(SKEWED.geom(), _bounds(SKEWED), pts)
    found = np.isfinite(theirs[:, 2])
    assert found.sum() > 1000
    diff = pr.distance[found] - theirs[found, 2]
    assert diff.max() <= 1e-12 * 8  # never farther than OCCT
    same = np.abs(diff) <= 1e-12 * 8
    assert same.sum() > 1000
    np.testing.assert_allclose(np.c_[pr.u, pr.v][found][same], theirs[found][same, :2], atol=1e-11, rtol=0)
    # the bounded patch, edges and corners included
    np.testing.assert_allclose(pr.distance[:600], face_distances(SKEWED.face(), pts[:600]), atol=1e-12 * 8,
                               rtol=0)


def test_three_point_plane_moved_and_reparametrized_and_not_a_parallelogram():
    pts = _points(500, 8)
    moved = SKEWED.rotated((1, 0, 0), (0.2, 1, 0.3), 41).scaled(1.7)
    assert type(moved) is sm.ThreePointPlane and moved._closest_parameters(pts) is not None
    np.testing.assert_allclose(sm.project(pts, moved).distance, face_distances(moved.face(), pts),
                               atol=1e-12 * 16, rtol=0)
    # knots [2, 2, 5, 5] x [-1, -1, 0, 0]: the closed form maps back to the net's own parameters
    net = SKEWED.control_points
    k = (np.array([2.0, 2, 5, 5]), np.array([-1.0, -1, 0, 0]))
    other = sm.ThreePointPlane(net, (1, 1), k)
    pr = sm.project(pts, other)
    np.testing.assert_allclose(other.points(pr.u, pr.v), pr.point, atol=1e-13)
    np.testing.assert_allclose(pr.distance, sm.project(pts, SKEWED).distance, atol=1e-13, rtol=0)
    # a bilinear net that is not a plane is given to the class directly: the search projects it
    warped = net.copy()
    warped[1, 1, 2] += 0.5
    twisted = sm.ThreePointPlane(warped, (1, 1), SKEWED.knots)
    assert twisted._closest_parameters(pts) is None
    np.testing.assert_allclose(sm.project(pts[:200], twisted).distance, face_distances(twisted.face(), pts[:200]),
                               atol=1e-9, rtol=0)
