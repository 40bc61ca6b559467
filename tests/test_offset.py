"""sm.offset / sm.thicken: tolerance held (OCCT projection), fold and crease pre-checks,
volumes against BRepGProp and Steiner's formula."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.occ.sample import distances_to_surface
from surfmod.occ.properties import gprops


def wavy(seed=3, degree=(3, 3), knots=None):
    rng = np.random.default_rng(seed)
    net = np.zeros((6, 6, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:6, 0:6]
    net[..., 2] = 0.4 * rng.normal(size=(6, 6))
    return sm.BSplineSurface(net, degree, knots)


def grid_uv(s, n=31):
    (u0, u1), (v0, v1) = s.domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, n), indexing="ij")
    return uu.ravel(), vv.ravel()


@pytest.mark.parametrize("d", [0.2, -0.15])
def test_offset_distance_checked_by_occt_projection(d):
    s = wavy()
    tol = 1e-5
    o = sm.offset(s, d, tol)
    assert o.max_deviation <= tol and o.degree == (3, 3)
    u, v = grid_uv(o)
    pts = o.points(u, v)
    dist = distances_to_surface(s.geom(), pts, (0, 1, 0, 1))
    inner = (u > 0.02) & (u < 0.98) & (v > 0.02) & (v < 0.98)    # projection is orthogonal inside
    assert np.abs(dist[inner] - abs(d)).max() <= tol
    exact = sm.OffsetSurface(s, d)
    assert np.abs(np.linalg.norm(pts - exact.points(u, v), axis=1)).max() <= tol
    assert sm.crosscheck(o).passed


def test_offset_of_a_cylinder_is_a_cylinder():
    cyl = sm.CylindricalSurface(2.0, u_range=(0, 1.5), v_range=(0, 3))
    for d, radius in ((0.5, 2.5), (-1.0, 1.0)):
        o = sm.offset(cyl, d, 1e-7)
        u, v = grid_uv(o, 41)
        np.testing.assert_allclose(np.linalg.norm(o.points(u, v)[:, :2], axis=1), radius, atol=1e-7)


def test_fold_precheck_names_the_region():
    cyl = sm.CylindricalSurface(2.0, u_range=(0, 1.5), v_range=(0, 3))
    with pytest.raises(sm.SurfmodError, match=r"distance: .*radius of curvature .*\(2\).*u in \[0, 1.5\]"):
        sm.offset(cyl, -2.0, 1e-6)
    s = wavy()
    c = s.curvatures(*grid_uv(s, 65))
    k = max(c.k1.max(), 0)
    with pytest.raises(sm.SurfmodError, match=r"u in \[.*\], v in \[") as info:
        sm.offset(s, 1.05 / k, 1e-5)
    assert "concave side" in str(info.value)
    sm.offset(s, 0.9 / k, 1e-4)     # inside the radius: fine


def test_crease_precheck():
    s = wavy(degree=(2, 2), knots=([0, 0, 0, .3, .5, .5, 1, 1, 1], [0, 0, 0, .3, .6, .8, 1, 1, 1]))
    with pytest.raises(sm.SurfmodError, match=r"crease along u = 0.5"):
        sm.offset(s, 0.05, 1e-5)
    left, right = s.split(u=0.5)
    assert sm.offset(left, 0.05, 1e-5).max_deviation <= 1e-5


def test_bad_arguments():
    s = wavy()
    with pytest.raises(sm.SurfmodError, match="distance"):
        sm.offset(s, 0.0)
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.offset(s, 0.1, -1)
    with pytest.raises(sm.SurfmodError, match="s:"):
        sm.offset("plate", 0.1)
    with pytest.raises(sm.SurfmodError, match="thickness"):
        sm.thicken(s, float("nan"))


def steiner_volume(s, t, n=8, order=30):
    """t A - t^2 int H dA + t^3/3 int K dA by Gauss-Legendre on the base."""
    x, w = np.polynomial.legendre.leggauss(order)
    nodes, weights = [], []
    for (lo, hi) in s.domain:
        br = np.linspace(lo, hi, n + 1)
        nodes.append(np.concatenate([a + (x + 1) / 2 * (b - a) for a, b in zip(br[:-1], br[1:])]))
        weights.append(np.concatenate([w * (b - a) / 2 for a, b in zip(br[:-1], br[1:])]))
    uu, vv = np.meshgrid(*nodes, indexing="ij")
    d = s.derivatives(uu, vv, 1)
    jac = np.linalg.norm(np.cross(d[..., 1, 0, :], d[..., 0, 1, :]), axis=-1)
    c = s.curvatures(uu, vv)
    return float((np.outer(*weights) * jac * (t - t * t * c.mean + t**3 / 3 * c.gaussian)).sum())


def test_thicken_volumes():
    cyl = sm.CylindricalSurface(2.0, u_range=(0, 1.5), v_range=(0, 3))
    for t, expected in ((0.5, 1.5 / 2 * (2.5**2 - 4) * 3), (-0.5, 1.5 / 2 * (4 - 1.5**2) * 3)):
        solid = sm.thicken(cyl, t, tolerance=1e-7)
        assert solid.is_valid
        assert gprops(solid.wrapped)["volume"] == pytest.approx(expected, rel=1e-7)
    s = wavy()
    solid = sm.thicken(s, 0.1, tolerance=1e-6)
    v = gprops(solid.wrapped)["volume"]
    assert v == pytest.approx(steiner_volume(s, 0.1), rel=1e-6)
    assert sm.mass_properties(solid).volume == pytest.approx(v, rel=1e-7)
    tube = sm.thicken(sm.CylindricalSurface(2.0, v_range=(0, 3)), 0.5, tolerance=1e-7)
    assert gprops(tube.wrapped)["volume"] == pytest.approx(np.pi * (2.5**2 - 4) * 3, rel=1e-7)
    with pytest.raises(sm.SurfmodError, match="thickness: .*radius of curvature"):
        sm.thicken(cyl, -2.5)
    mid = sm.thicken(cyl, 0.5, tolerance=1e-7, symmetric=True)      # radii 1.75 .. 2.25
    assert gprops(mid.wrapped)["volume"] == pytest.approx(1.5 / 2 * (2.25**2 - 1.75**2) * 3, rel=1e-7)


def test_tiny_tolerances_refused_before_the_big_fits(monkeypatch):
    """Issue 25: offset(…, 1e-9) ran for minutes of ever larger fits whose error stalled
    at the least-squares round-off (~4e-11 of the size).  Below FIT_FLOOR of the size it is
    refused at once; above it, a tolerance whose h^4 span count passes MAX_SPANS is refused
    before that fit is made."""
    from surfmod.construct import offset as offset_module

    s = wavy()
    size = offset_module.model_size(s) + 0.5
    fits = []
    original = offset_module._fit
    monkeypatch.setattr(offset_module, "_fit", lambda *a, **k: fits.append(a[1].size * a[2].size) or original(*a, **k))
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: .* below what a bicubic fit can reach"):
        sm.offset(s, 0.5, 0.5 * offset_module.FIT_FLOOR * size)
    assert fits == []
    monkeypatch.setattr(offset_module, "MAX_SPANS", 400)
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: 1e-07 would need at least [\d,]+ bicubic spans"):
        sm.offset(s, 0.5, 1e-7)
    assert max(fits) <= 400 * 2  # breakpoints of every fit made stayed within the cap
