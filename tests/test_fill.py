"""sm.fill: 3-, 4- and 5-sided G1 fills, measured with sm.continuity and OCCT's
LocalAnalysis, beside OCCT's BRepOffsetAPI_MakeFilling on the same holes."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.construct.fill import occt_fill


def four_sided_hole():
    rng = np.random.default_rng(3)
    net = np.zeros((7, 7, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:7, 0:7]
    net[..., 2] = 0.4 * rng.normal(size=(7, 7))
    s = sm.BSplineSurface(net)
    r = [(0, .35), (.35, .65), (.65, 1)]
    p = {(i, j): s.segment(r[i], r[j]) for i in range(3) for j in range(3)}
    return [(p[1, 0], "v1"), (p[2, 1], "u0"), (p[1, 2], "v0"), (p[0, 1], "u1")], p[1, 1]


def corner_hole(radius=1.0):
    """The corner of a box rounded with three cylinders of one radius: a 3-sided hole."""
    x = sm.CylindricalSurface(radius, (0, 0, 0), (1, 0, 0), (0, 1, 0), u_range=(0, np.pi / 2), v_range=(-3, 0))
    y = sm.CylindricalSurface(radius, (0, 0, 0), (0, 1, 0), (0, 0, 1), u_range=(0, np.pi / 2), v_range=(-3, 0))
    z = sm.CylindricalSurface(radius, (0, 0, 0), (0, 0, 1), (1, 0, 0), u_range=(0, np.pi / 2), v_range=(-3, 0))
    return [(x, "v1"), (y, "v1"), (z, "v1")]


def pentagon_hole():
    """Five degree-(2, 2) patches of the paraboloid z = (x^2 + 2 y^2)/8 around a pentagon."""
    f = lambda x, y: (x * x + 2 * y * y) / 8  # noqa: E731
    ang = np.pi / 2 + 2 * np.pi * np.arange(5) / 5
    inner, outer = np.stack([np.cos(ang), np.sin(ang)], 1), 2 * np.stack([np.cos(ang), np.sin(ang)], 1)
    t = np.array([0.0, 0.5, 1.0])
    bern = np.stack([(1 - t) ** 2, 2 * t * (1 - t), t**2], 1)       # Bernstein at 0, 1/2, 1
    sides = []
    for k in range(5):
        a, b, c, d = inner[k], inner[(k + 1) % 5], outer[k], outer[(k + 1) % 5]
        s, w = np.meshgrid(t, t, indexing="ij")
        xy = ((1 - s) * (1 - w))[..., None] * a + (s * (1 - w))[..., None] * b + ((1 - s) * w)[..., None] * c \
            + (s * w)[..., None] * d
        pts = np.concatenate([xy, f(xy[..., 0], xy[..., 1])[..., None]], axis=-1)
        inv = np.linalg.inv(bern)
        net = np.einsum("ia,jb,abk->ijk", inv, inv, pts)              # exact: z is biquadratic
        sides.append((sm.BezierSurface(net), "v0"))
    return sides


def test_four_sided_fill_is_g1_along_every_side():
    boundary, removed = four_sided_hole()
    f = sm.fill(boundary, tolerance=1e-6)
    assert len(f) == 1 and f.n_sides == 4
    assert [c.matched for c in f.corners] == ["G1"] * 4        # one smooth skin: C1 through the corners
    for nb, side in boundary:
        c = sm.continuity(nb, f[0], samples=41, occt=True)
        assert c.label.startswith(f"a.{side}")
        assert c.g0 < 1e-12
        assert c.angle[1:-1].max() < 1e-12          # exact along the side
        assert c.g1 < 1e-12                         # the corner samples too
        assert np.nanmax(c.occt[:, 1]) < 1e-3       # OCCT sees the bicubic twin (tolerance 1e-6)
    assert sm.crosscheck(f[0], samples=16).passed
    # a G0 fill of the same hole has a visible crease
    g0 = sm.fill(boundary, "G0")
    assert sm.continuity(boundary[0][0], g0[0]).g1 > 1e-2


def test_three_sided_vertex_blend_between_fillets():
    boundary = corner_hole()
    f = sm.fill(boundary)
    assert len(f) == 3
    found = 0
    for nb, side in boundary:
        for patch in f:
            try:
                c = sm.continuity(patch, nb, samples=21)    # the patch's side lies on nb's side
            except sm.SurfmodError:
                continue
            found += 1
            assert c.g0 < 1e-12 and c.g1 < 1e-6
    assert found == 6              # each fillet end is shared by two patches
    # the patches join each other smoothly (one underlying surface)
    inner = sm.continuity(f[0], f[1], samples=21)
    assert inner.g0 < 1e-12 and inner.g1 < 1e-9
    # near the sphere octant it replaces; first-order ribbons bulge, tension pulls them in
    def bulge(fill_):
        pts = np.concatenate([p.grid(np.linspace(0, 1, 9), np.linspace(0, 1, 9)).reshape(-1, 3) for p in fill_])
        return np.abs(np.linalg.norm(pts, axis=1) - 1.0).max()

    assert bulge(f) < 0.25
    assert bulge(sm.fill(boundary, tension=0.6)) < bulge(f)


def test_five_sided_hole_in_a_paraboloid():
    boundary = pentagon_hole()
    f = sm.fill(boundary)
    assert len(f) == 5
    angles = []
    # patch k has its corner at vertex k, between sides k - 1 and k: each side is shared by
    # two patches (sm.continuity refuses a pair that shares no side; asking every pair
    # spent 15 of its 25 calls on those refusals)
    for k, patch in enumerate(f):
        for j in (k, k - 1):
            c = sm.continuity(patch, boundary[j][0], samples=21)
            assert c.g0 < 1e-12
            angles.append(c.g1)
    assert len(angles) == 10 and max(angles) < 1e-6
    pts = np.concatenate([p.grid(np.linspace(0, 1, 7), np.linspace(0, 1, 7)).reshape(-1, 3) for p in f])
    # first-order ribbons carry tangent planes, not curvature: the centre sits a little low
    assert np.abs(pts[:, 2] - (pts[:, 0] ** 2 + 2 * pts[:, 1] ** 2) / 8).max() < 0.15


def test_occt_filling_on_the_same_four_sided_hole():
    boundary, _ = four_sided_hole()
    ours = sm.fill(boundary)
    theirs = occt_fill(boundary)
    worst_ours = max(sm.continuity(nb, ours[0], samples=21).g1 for nb, _ in boundary)
    worst_occt = max(sm.continuity(nb, theirs, samples=21).g1 for nb, _ in boundary)
    assert worst_ours < 1e-6 < worst_occt


def test_bad_boundaries():
    boundary, _ = four_sided_hole()
    with pytest.raises(sm.SurfmodError, match="boundary: expected a list of 3, 4 or 5"):
        sm.fill(boundary[:2])
    with pytest.raises(sm.SurfmodError, match=r"boundary\[1\]: side"):
        sm.fill([boundary[0], (boundary[1][0], "w1"), *boundary[2:]])
    with pytest.raises(sm.SurfmodError, match=r"boundary\[2\]: does not start"):
        sm.fill([boundary[0], boundary[1], (boundary[2][0].translated((0, 0, 1)), "v0"), boundary[3]])
    with pytest.raises(sm.SurfmodError, match="continuity"):
        sm.fill(boundary, "G3")
    with pytest.raises(sm.SurfmodError, match=r"boundary\[0\]"):
        sm.fill([42, *boundary[1:]])


def test_g2_fill_matches_the_neighbours_curvature_along_the_sides():
    boundary, _ = four_sided_hole()
    g1, g2 = sm.fill(boundary, "G1"), sm.fill(boundary, "G2")
    for nb, side in boundary:
        c2 = sm.continuity(nb, g2[0], samples=31)
        scale = c2.g2 / c2.g2_relative
        assert c2.g0 < 1e-12 and c2.angle[1:-1].max() < 1e-12
        # the 2-jets agree along the side, corners included (one smooth skin: compatible corners)
        assert (c2.jump / scale).max() < 1e-9
        c1 = sm.continuity(nb, g1[0], samples=31)
        assert (c1.jump[1:-1] / scale).max() > 1e-2          # the G1 fill does not
    corner = corner_hole()       # curvatures disagree at the corners: see test_fill_g2
    for patch in sm.fill(corner, "G2", allow_singular_corners=True):
        for nb, _ in corner:
            try:
                c = sm.continuity(patch, nb, samples=21)
            except sm.SurfmodError:
                continue
            assert c.g0 < 1e-12 and c.angle[1:-1].max() < 1e-12 and c.jump[1:-1].max() < 1e-9
