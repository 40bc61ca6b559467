"""sm.fill(..., "G2"): curvature-continuous fills of 3-, 4- and 5-sided holes cut out of
one smooth surface (a paraboloid, a bicubic Bezier patch, a cubic B-spline skin),
G2 along every side *including the corners*, measured with sm.continuity and with
OCCT's LocalAnalysis_SurfaceContinuity; and the corners where G2 is impossible."""

import math

import numpy as np
import pytest
from test_fill import corner_hole, four_sided_hole

import surfmod as sm
from surfmod.construct.fill import occt_fill
from surfmod.occ.local_analysis import local_analysis

SAMPLES = 60


def _bernstein_inverse(p):
    t = np.linspace(0.0, 1.0, p + 1)
    return np.linalg.inv(np.array([[math.comb(p, k) * x**k * (1 - x) ** (p - k) for k in range(p + 1)] for x in t]))


def paraboloid(x, y):
    return np.stack([x, y, (x * x + 2 * y * y) / 8], axis=-1)


def bezier_base():
    rng = np.random.default_rng(11)
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4] * 2.0
    net[..., 2] = rng.normal(size=(4, 4))
    return sm.BezierSurface(net)


def polygon_hole(n, base="paraboloid"):
    """The n quads between an inner and an outer n-gon, in the (x, y) plane of the
    paraboloid z = (x^2 + 2 y^2)/8 (exact biquadratic neighbours) or in the parameter
    square of a bicubic Bezier patch (exact degree-(6, 6) neighbours).  Returns the
    boundary and ``surface(x, y)`` of the surface the hole was cut from."""
    if base == "paraboloid":
        surface, degree, centre, inner_r, outer_r = paraboloid, 2, np.zeros(2), 1.0, 2.0
    else:
        patch = bezier_base()
        surface, degree, centre, inner_r, outer_r = patch.points, 6, np.full(2, 0.5), 0.2, 0.45
    ang = np.pi / 2 + 2 * np.pi * np.arange(n) / n + 0.3
    ring = np.stack([np.cos(ang), np.sin(ang)], 1)
    inner, outer = centre + inner_r * ring, centre + outer_r * ring
    t = np.linspace(0.0, 1.0, degree + 1)
    inv = _bernstein_inverse(degree)
    sides = []
    for k in range(n):
        a, b, c, d = inner[k], inner[(k + 1) % n], outer[k], outer[(k + 1) % n]
        s, w = np.meshgrid(t, t, indexing="ij")
        xy = ((1 - s) * (1 - w))[..., None] * a + (s * (1 - w))[..., None] * b + ((1 - s) * w)[..., None] * c \
            + (s * w)[..., None] * d
        pts = surface(xy[..., 0].ravel(), xy[..., 1].ravel()).reshape(xy.shape[:2] + (3,))
        sides.append((sm.BezierSurface(np.einsum("ia,jb,abk->ijk", inv, inv, pts)), "v0"))
    return sides, surface


def pairs(fill, boundary):
    """(patch, neighbour) pairs sharing a side of the hole: the one patch of a 4-sided
    fill meets all four; patch k of a 3- or 5-sided fill has its corner at vertex k, between
    sides k - 1 and k (sm.continuity checks that they really share a side)."""
    n = len(boundary)
    if n == 4:
        return [(fill[0], nb) for nb, _ in boundary]
    return [(fill[k], boundary[j][0]) for k in range(n) for j in (k, k - 1)]


def osculating(d):
    """The biquadratic Bezier patch with the 2-jet ``d`` (a fill's derivatives at a point,
    ``d[i, j]`` the i-th in u and j-th in v) at its own parameters (1/2, 1/2): OCCT's
    LocalAnalysis then sees the fill's derivatives."""
    t = np.linspace(-0.5, 0.5, 3)
    a, b = np.meshgrid(t, t, indexing="ij")
    pts = (d[0, 0] + a[..., None] * d[1, 0] + b[..., None] * d[0, 1]
           + 0.5 * (a * a)[..., None] * d[2, 0] + (a * b)[..., None] * d[1, 1] + 0.5 * (b * b)[..., None] * d[0, 2])
    inv = _bernstein_inverse(2)
    return sm.BezierSurface(np.einsum("ia,jb,abk->ijk", inv, inv, pts))


def occt_g2(patch, nb, samples=SAMPLES):
    """OCCT's (C0, G1 angle, G2 curvature gap) at ``samples`` points of the shared side,
    the fill side given to OCCT through its osculating patch at each sample."""
    c = sm.continuity(patch, nb, samples=samples)
    # every sample's jets in one call each: a fill's evaluation costs about as much for
    # one point as for sixty (six times the test's time, point by point)
    jets = patch.derivatives(c.params_a[:, 0], c.params_a[:, 1], 2)
    nbs = nb.derivatives(c.params_b[:, 0], c.params_b[:, 1], 1)
    rows = []
    for d, db, uv_b in zip(jets, nbs, c.params_b):
        flip = np.cross(d[1, 0], d[0, 1]) @ np.cross(db[1, 0], db[0, 1]) < 0   # OCCT wants like normals
        rows.append(local_analysis(nb.geom(), uv_b[None], osculating(d).geom(), np.array([[0.5, 0.5]]),
                                   reverse_b=flip)[0])
    return c, np.array(rows)


@pytest.mark.parametrize("base", ["paraboloid", "bezier"])
@pytest.mark.parametrize("n", [3, 4, 5])
def test_g2_fill_of_a_hole_cut_from_one_smooth_surface(n, base):
    boundary, _ = polygon_hole(n, base)
    f = sm.fill(boundary, "G2")
    assert len(f) == (1 if n == 4 else n)
    assert [c.matched for c in f.corners] == ["G2"] * n
    assert max(c.angle for c in f.corners) < 1e-12 and max(c.curvature for c in f.corners) < 1e-9
    for patch, nb in pairs(f, boundary):
        # 60 samples per side: a side of a 3- or 5-sided hole is shared by two patches
        c, occt = occt_g2(patch, nb, SAMPLES if n == 4 else SAMPLES // 2)
        scale = c.g2 / c.g2_relative if c.g2_relative > 0 else 1.0
        # the whole side, both corner samples included
        assert c.g0 < 1e-12 and c.g1 < 1e-9 and c.g2_relative < 1e-6
        assert c.g2_relative < 1e-9                     # in fact to rounding
        assert np.all(np.isfinite(occt))
        assert occt[:, 0].max() < 1e-12 and occt[:, 1].max() < 1e-9
        assert occt[:, 2].max() / scale < 1e-6


def test_g2_four_sided_hole_in_a_bspline_skin_beside_makefilling():
    boundary, _ = four_sided_hole()
    f = sm.fill(boundary, "G2")
    worst = 0.0
    for nb, _ in boundary:
        c = sm.continuity(nb, f[0], samples=SAMPLES)
        assert c.g0 < 1e-12 and c.g1 < 1e-9
        worst = max(worst, c.g2_relative)
    assert worst < 1e-9
    theirs = occt_fill(boundary)                  # G1 constraints: OCCT refuses G2 ones
    occt_worst = max(sm.continuity(nb, theirs, samples=SAMPLES).g2_relative for nb, _ in boundary)
    assert worst < 1e-6 and occt_worst > 1e-2


def test_g2_fill_is_c2_through_its_corners():
    """At a corner of a compatible hole the fill has the cut-out surface's 2-jet
    (closed form: Gaussian and mean curvature of the paraboloid), and nearby interior
    points converge to it."""
    boundary, _ = polygon_hole(5)
    f = sm.fill(boundary, "G2")
    patch = f[0]                                  # its corner (0, 0) is a polygon vertex
    d = patch.derivatives(np.array([0.0]), np.array([0.0]), 2)[0]
    x, y = d[0, 0, :2]
    fx, fy, fxx, fyy = x / 4, y / 2, 0.25, 0.5
    w = 1 + fx * fx + fy * fy
    k_exact = fxx * fyy / w**2
    h_exact = ((1 + fy * fy) * fxx + (1 + fx * fx) * fyy) / (2 * w**1.5)

    def curvatures(dd):
        n = np.cross(dd[1, 0], dd[0, 1])
        n /= np.linalg.norm(n)
        e, ff, g = dd[1, 0] @ dd[1, 0], dd[1, 0] @ dd[0, 1], dd[0, 1] @ dd[0, 1]
        l, m, nn = dd[2, 0] @ n, dd[1, 1] @ n, dd[0, 2] @ n
        return (l * nn - m * m) / (e * g - ff * ff), (e * nn - 2 * ff * m + g * l) / (2 * (e * g - ff * ff))

    k, h = curvatures(d)
    assert abs(k - k_exact) < 1e-9 * k_exact and abs(abs(h) - h_exact) < 1e-9 * h_exact
    for direction in ((1.0, 1.0), (1.0, 0.2), (0.2, 1.0)):
        errors = []
        for step in (1e-2, 1e-3, 1e-4):
            dd = patch.derivatives(np.array([step * direction[0]]), np.array([step * direction[1]]), 2)[0]
            kk, hh = curvatures(dd)
            errors.append(max(abs(kk - k_exact) / k_exact, abs(abs(hh) - h_exact) / h_exact))
        assert errors[2] < 1e-3 and errors[2] < errors[0]      # converges to the corner's curvature


def test_g2_refused_where_the_neighbours_disagree_in_curvature():
    """Three fillets of radius R meeting at a box corner: at each corner two cylinders
    with perpendicular axes meet, principal curvature 1/R in perpendicular directions,
    so their normal curvatures differ by 1/R (relative 1): no fill smooth at the corner
    is G2 to both.  G1 is fine; G2 along the open sides is available on request."""
    boundary = corner_hole()
    with pytest.raises(sm.SurfmodError, match=r"continuity: G2 is impossible at the boundary\[0\] / boundary\[1\] "
                                              r"corner at \[0\.0, 0\.0, 1\.0\].*differ by 1 \(relative\)"):
        sm.fill(boundary, "G2")
    g1 = sm.fill(boundary, "G1")
    assert [c.matched for c in g1.corners] == ["G1"] * 3
    relaxed = sm.fill(boundary, "G2", allow_singular_corners=True)
    assert [c.matched for c in relaxed.corners] == ["G1"] * 3
    assert all(abs(c.curvature - 1.0) < 1e-12 and c.angle < 1e-12 for c in relaxed.corners)
    for patch, nb in pairs(relaxed, boundary):
        c = sm.continuity(patch, nb, samples=SAMPLES)
        assert c.g0 < 1e-12 and c.g1 < 1e-9
        relative = c.jump / (c.g2 / c.g2_relative)
        assert relative[1:-1].max() < 1e-9              # G2 along the open side
        assert relative[[0, -1]].max() > 0.1            # not at its corner point


def test_g1_fill_refused_where_the_tangent_planes_disagree():
    """A square hole in the plane z = 0 whose fourth neighbour is tilted about its side:
    at its two corners the normals differ by the tilt angle."""
    tilt = 0.2
    sides = [(sm.plane((0, -1, 0), (1, -1, 0), (0, 0, 0)), "v1"),
             (sm.plane((1, 0, 0), (1 + math.cos(tilt), 0, math.sin(tilt)), (1, 1, 0)), "u0"),
             (sm.plane((0, 1, 0), (1, 1, 0), (0, 2, 0)), "v0"),
             (sm.plane((-1, 0, 0), (0, 0, 0), (-1, 1, 0)), "u1")]
    with pytest.raises(sm.SurfmodError, match=r"boundary: the neighbours' tangent planes differ by 0\.2 rad "
                                              r"at the boundary\[0\] / boundary\[1\] corner"):
        sm.fill(sides)
    f = sm.fill(sides, allow_singular_corners=True)
    assert [c.matched for c in f.corners] == ["none", "none", "G1", "G1"]
    assert abs(f.corners[0].angle - tilt) < 1e-12
    for nb, _ in sides:
        c = sm.continuity(nb, f[0], samples=SAMPLES)
        assert c.g0 < 1e-12 and c.angle[1:-1].max() < 1e-12     # G1 up to the singular corners


def test_g1_fill_is_exact_at_compatible_corners_too():
    for boundary in (four_sided_hole()[0], polygon_hole(3)[0], corner_hole()):
        f = sm.fill(boundary, "G1")
        for patch, nb in pairs(f, boundary):
            assert sm.continuity(patch, nb, samples=SAMPLES).g1 < 1e-12


def test_non_convex_hole_is_refused_at_its_reflex_corner():
    pts = np.array([(0, 0, 0), (2, 0, 0), (2, 2, 0), (1, 0.8, 0), (0, 2, 0)], float)
    sides = []
    for k in range(5):
        a, b = pts[k], pts[(k + 1) % 5]
        out = np.array([b[1] - a[1], a[0] - b[0], 0.0])
        sides.append((sm.plane(a, b, a + out / np.linalg.norm(out)), "v0"))
    with pytest.raises(sm.SurfmodError, match=r"not convex at the boundary\[2\] / boundary\[3\] corner "
                                              r"at \[1\.0, 0\.8, 0\.0\]"):
        sm.fill(sides)
    f = sm.fill(sides, allow_singular_corners=True)
    assert [c.matched for c in f.corners] == ["G1", "G1", "none", "G1", "G1"]
    for patch, nb in pairs(f, sides):
        assert sm.continuity(patch, nb, samples=20).g0 < 1e-12


def test_continuity_does_not_depend_on_argument_order():
    """The side of a 3-sided fill's patch covers only half of its neighbour's side:
    sm.continuity samples the shorter side whichever way round it is called, reports the
    same gaps, angles and jumps, and signs both curvatures by the first argument's normal."""
    boundary, _ = polygon_hole(3)
    fill = sm.fill(boundary, continuity="G2")
    for patch, nb in pairs(fill, boundary):
        ab = sm.continuity(patch, nb, samples=20)
        ba = sm.continuity(nb, patch, samples=20)
        assert ba.label == f"a.{ab.label.split('b.')[1]} | b.{ab.label.split(' | ')[0][2:]}"
        np.testing.assert_allclose(ba.points, ab.points, rtol=0, atol=1e-12)
        np.testing.assert_allclose(ba.params_a, ab.params_b, rtol=0, atol=1e-12)
        np.testing.assert_allclose(ba.params_b, ab.params_a, rtol=0, atol=1e-12)
        # curvatures are signed by the first argument's normal: the fill's patches face
        # the other way from their neighbours, so swapping the arguments flips the signs
        n_patch = patch.normals(*ab.params_a.T)
        n_nb = nb.normals(*ab.params_b.T)
        sign = np.sign(np.einsum("ij,ij->i", n_patch, n_nb))
        assert np.all(np.abs(np.einsum("ij,ij->i", n_patch, n_nb)) > 1 - 1e-12)
        np.testing.assert_allclose(ba.curvature_a, sign * ab.curvature_b, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ba.curvature_b, sign * ab.curvature_a, rtol=1e-9, atol=1e-12)
        assert ba.g2_relative < 1e-9 and ba.g1 < 1e-12
