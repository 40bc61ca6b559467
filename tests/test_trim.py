"""Trimming by (u, v) loops: OCCT face area (BRepGProp) vs NumPy Green's-theorem quadrature
vs closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps

import surfmod as sm
from surfmod.ops.trim import trimmed_area


def face_area(face, eps: float = 1e-10) -> float:
    """OCCT's area of a face (``BRepGProp.SurfaceProperties_s`` at relative accuracy ``eps``)."""
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(getattr(face, "wrapped", face), props, eps, False)
    return float(props.Mass())


def face_is_valid(face) -> bool:
    return BRepCheck_Analyzer(getattr(face, "wrapped", face)).IsValid()


def _nurbs():
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.linspace(0, 4, 6), np.linspace(0, 3, 5), indexing="ij")
    net = np.stack([x, y, rng.uniform(-1, 1, (6, 5))], -1)
    return sm.BSplineSurface(net, (3, 2), None, rng.uniform(0.5, 2, (6, 5)))


def _ellipse(cx, cy, rx, ry, n=40, clockwise=False):
    th = np.linspace(0, 2 * np.pi, n + 1)
    if clockwise:
        th = th[::-1]
    pts = np.c_[cx + rx * np.cos(th), cy + ry * np.sin(th)]
    pts[-1] = pts[0]
    return pts


def _nurbs_circle(cx, cy, r):
    """The exact rational quadratic circle in the z = 0 plane (9 control points)."""
    c = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], float)
    pts = np.c_[cx + r * c[:, 0], cy + r * c[:, 1], np.zeros(9)]
    w = np.array([1, 2**-0.5] * 4 + [1])
    knots = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
    return sm.BSplineCurve(pts, 2, knots, w)


def _polygon_area(p):
    return 0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))


def test_plane_closed_form():
    """On the affine plane P0 + u e1 + v e2 the area is |e1 x e2| times the uv area."""
    s = sm.plane((0, 0, 0), (2, 0, 0), (0.5, 3, 0))
    loops = [_ellipse(0.5, 0.5, 0.3, 0.35), _ellipse(0.45, 0.5, 0.1, 0.1)]
    expected = 6.0 * (_polygon_area(loops[0]) - abs(_polygon_area(loops[1])))
    face = sm.trim(s, loops)
    assert face_is_valid(face)
    assert face_area(face) == pytest.approx(expected, rel=1e-13)
    assert trimmed_area(s, loops) == pytest.approx(expected, rel=1e-13)
    # an exact circle as a rational B-spline p-curve: area = |e1 x e2| pi r^2
    circle = _nurbs_circle(0.5, 0.5, 0.25)
    assert face_area(sm.trim(s, circle)) == pytest.approx(6.0 * np.pi * 0.25**2, rel=1e-10)
    assert trimmed_area(s, circle) == pytest.approx(6.0 * np.pi * 0.25**2, rel=1e-12)


def test_trimmed_nurbs_area_matches_brepgprop():
    s = _nurbs()
    outer = _ellipse(0.5, 0.5, 0.3, 0.35)
    hole = _ellipse(0.5, 0.45, 0.1, 0.1)
    for boundary in (outer, [outer, hole]):
        face = sm.trim(s, boundary)
        assert face_is_valid(face)
        occ = face_area(face, 1e-10)
        mine = trimmed_area(s, boundary)
        assert mine == pytest.approx(occ, rel=1e-9)
    # hole area = outer-only minus with-hole
    assert trimmed_area(s, hole) == pytest.approx(trimmed_area(s, outer) - trimmed_area(s, [outer, hole]), rel=1e-11)


def test_orientation_is_fixed_automatically():
    s = _nurbs()
    cw = _ellipse(0.4, 0.6, 0.2, 0.25, clockwise=True)
    ccw = _ellipse(0.4, 0.6, 0.2, 0.25)
    assert trimmed_area(s, cw) == pytest.approx(trimmed_area(s, ccw), rel=1e-14)
    assert face_area(sm.trim(s, cw)) == pytest.approx(face_area(sm.trim(s, ccw)), rel=1e-12)
    hole_ccw = _ellipse(0.4, 0.6, 0.05, 0.05)
    assert face_area(sm.trim(s, [ccw, hole_ccw])) < face_area(sm.trim(s, ccw))


def test_bspline_pcurve_loop_on_nurbs():
    s = _nurbs()
    circle = _nurbs_circle(0.55, 0.45, 0.3)
    face = sm.trim(s, circle)
    assert face_is_valid(face)
    assert trimmed_area(s, circle) == pytest.approx(face_area(face, 1e-10), rel=1e-8)


def test_whole_domain_square_equals_full_patch_area():
    s = _nurbs()
    square = [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)]
    # full-domain tensor Gauss quadrature split at the knots
    x, w = np.polynomial.legendre.leggauss(30)

    def composite(breaks):
        nodes = [a + (x + 1) / 2 * (b - a) for a, b in zip(breaks[:-1], breaks[1:])]
        weights = [w * (b - a) / 2 for a, b in zip(breaks[:-1], breaks[1:])]
        return np.concatenate(nodes), np.concatenate(weights)

    uu, wu = composite(np.unique(s.knots[0]))
    vv, wv = composite(np.unique(s.knots[1]))
    d = s.grid_derivatives(uu, vv, 1)
    direct = np.einsum("ij,i,j->", np.linalg.norm(np.cross(d[..., 1, 0, :], d[..., 0, 1, :]), axis=-1), wu, wv)
    assert trimmed_area(s, square) == pytest.approx(direct, rel=1e-13)
    # OCCT converges slowly on the untrimmed rectangle: 4e-7 at eps = 1e-10
    assert face_area(sm.trim(s, square), 1e-10) == pytest.approx(direct, rel=1e-6)


@pytest.mark.parametrize(
    "boundary, match",
    [
        ([(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)], "not closed"),
        ([(0.1, 0.1), (0.9, 0.1), (0.1, 0.1)], "at least 4"),
        ([(0.1, 0.1), (1.5, 0.1), (0.9, 0.9), (0.1, 0.1)], "leaves the parameter domain"),
        ([(0.1, 0.1), (0.5, 0.5), (0.9, 0.9), (0.1, 0.1)], "encloses no area"),
        ([(0.1, np.nan), (0.9, 0.1), (0.9, 0.9), (0.1, 0.1)], "NaN"),
        (np.zeros((5, 3)), "last axis"),
        ([], "no loop"),
        ("square", "boundary_curve_uv"),
        (sm.BSplineCurve([(0.1, 0.1, 0), (0.5, 0.9, 0), (0.9, 0.1, 0)], 2), "not closed"),
        (sm.BSplineCurve([(0.1, 0.1, 0), (0.5, 0.9, 1), (0.1, 0.1, 0)], 2), "z = 0"),
    ],
)
def test_bad_trim_input(boundary, match):
    s = _nurbs()
    with pytest.raises(sm.SurfmodError, match="boundary_curve_uv"):
        sm.trim(s, boundary)
    with pytest.raises(sm.SurfmodError, match=match):
        trimmed_area(s, boundary)


def test_bad_trim_hole_names_its_index_and_bad_surface():
    s = _nurbs()
    with pytest.raises(sm.SurfmodError, match=r"boundary_curve_uv\[1\].*not closed"):
        sm.trim(s, [_ellipse(0.5, 0.5, 0.3, 0.3), _ellipse(0.5, 0.5, 0.1, 0.1)[:-1]])
    with pytest.raises(sm.SurfmodError, match="s: expected a surfmod Surface"):
        sm.trim("surface", _ellipse(0.5, 0.5, 0.3, 0.3))
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.trim(s, _ellipse(0.5, 0.5, 0.3, 0.3), tolerance=-1)


def test_sphere_patch_closed_form():
    """An octant of the sphere of radius 2 (u in [0, pi/2], v in [0, pi/2]): area 2 pi;
    a latitude band cut by a polygon in (u, v): r^2 (u1 - u0) (sin v1 - sin v0)."""
    s = sm.sphere(2.0)
    h = np.pi / 2
    octant = [(0, 0), (h, 0), (h, h), (0, h), (0, 0)]
    assert trimmed_area(s, octant) == pytest.approx(2 * np.pi, rel=1e-12)
    assert face_area(sm.trim(s, octant), 1e-10) == pytest.approx(2 * np.pi, rel=1e-8)
    band = [(0.5, 0.1), (2.5, 0.1), (2.5, 0.9), (0.5, 0.9), (0.5, 0.1)]
    expected = 4.0 * 2.0 * (np.sin(0.9) - np.sin(0.1))
    assert trimmed_area(s, band) == pytest.approx(expected, rel=1e-12)
    assert face_area(sm.trim(s, band), 1e-10) == pytest.approx(expected, rel=1e-8)
