"""Shadows under parallel light vs closed forms, a rasterized union of the projected mesh
and OCCT's exact hidden-line outlines (HLRBRep)."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from twins.hlr import hlr_outline
from surfmod.ops.marching import segment_distances

LIGHT = np.array([0.5, 0.3, -1.0])
PLANE = ((0.0, 0.0, -2.0), (0.0, 0.2, 1.0))


def _nurbs():
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.linspace(0, 4, 7), np.linspace(0, 3, 6), indexing="ij")
    net = np.stack([x, y, rng.uniform(-1, 1, (7, 6)) * 1.5], -1)
    return sm.BSplineSurface(net, (3, 3), None, rng.uniform(0.5, 2, (7, 6)))


def _raster_union_area(q, pixels=500):
    """Area covered by the triangles of a projected grid ``q (n, m, 2)`` (pixel count)."""
    tri = np.concatenate(
        [
            np.stack([q[:-1, :-1], q[1:, :-1], q[1:, 1:]], -2).reshape(-1, 3, 2),
            np.stack([q[:-1, :-1], q[1:, 1:], q[:-1, 1:]], -2).reshape(-1, 3, 2),
        ]
    )
    lo, hi = q.reshape(-1, 2).min(0), q.reshape(-1, 2).max(0)
    xs, ys = np.linspace(lo[0], hi[0], pixels), np.linspace(lo[1], hi[1], pixels)
    px, py = xs[1] - xs[0], ys[1] - ys[0]
    mask = np.zeros((pixels, pixels), bool)
    for a0, b0, c0 in tri:
        t = np.array([a0, b0, c0])
        i0, i1 = int((t[:, 0].min() - lo[0]) / px), int(np.ceil((t[:, 0].max() - lo[0]) / px)) + 1
        j0, j1 = int((t[:, 1].min() - lo[1]) / py), int(np.ceil((t[:, 1].max() - lo[1]) / py)) + 1
        X, Y = np.meshgrid(xs[i0:i1], ys[j0:j1], indexing="ij")
        v0, v1 = b0 - a0, c0 - a0
        det = v0[0] * v1[1] - v0[1] * v1[0]
        if abs(det) < 1e-300:
            continue
        rx, ry = X - a0[0], Y - a0[1]
        be, ga = (rx * v1[1] - ry * v1[0]) / det, (v0[0] * ry - v0[1] * rx) / det
        mask[i0:i1, j0:j1] |= (be >= 0) & (ga >= 0) & (be + ga <= 1)
    return mask.sum() * px * py


def test_flat_patch_closed_form():
    """A flat parallelogram: shadow area = |e1 x e2 . L| / |L . n| (n the plane normal)."""
    e1, e2 = np.array([2.0, 0.0, 0.5]), np.array([0.3, 1.5, 0.0])
    s = sm.plane((0, 0, 1), e1, e2)  # points: p1 = e1, p2 = e2 (corner (0,0,1))
    e1, e2 = np.array(e1) - (0, 0, 1), np.array(e2) - (0, 0, 1)
    light = LIGHT / np.linalg.norm(LIGHT)
    n = np.array(PLANE[1]) / np.linalg.norm(PLANE[1])
    sh = sm.shadow(s, LIGHT, PLANE)
    expected = abs(np.cross(e1, e2) @ light) / abs(light @ n)
    assert sh.complete and len(sh.outline) == 1 and sh.silhouettes == []
    assert sh.area == pytest.approx(expected, rel=1e-12)
    # outline on the plane, made of projected corners
    assert np.abs((sh.outline[0] - PLANE[0]) @ n).max() < 1e-12


def test_nurbs_shadow_area_matches_raster_union():
    s = _nurbs()
    sh = sm.shadow(s, LIGHT, PLANE)
    assert sh.complete and len(sh.outline) == 1 and len(sh.silhouettes) >= 1
    n = np.array(PLANE[1]) / np.linalg.norm(PLANE[1])
    for c in sh.outline + sh.boundary + sh.silhouettes:
        assert np.abs((c - PLANE[0]) @ n).max() < 1e-12
    # silhouette points graze the light: N . L = 0 at their pre-images
    us = np.linspace(0, 1, 161)
    g = s.grid(us, us)
    light = LIGHT / np.linalg.norm(LIGHT)
    shadow_pts = g - (((g - PLANE[0]) @ n) / (light @ n))[..., None] * light
    area = _raster_union_area(sh.to_2d(shadow_pts))
    assert sh.area == pytest.approx(area, rel=2e-3)
    assert sh.area > 0  # outer loop counter-clockwise


def test_silhouettes_match_occt_hidden_line_outline():
    s = _nurbs()
    sh = sm.shadow(s, LIGHT, PLANE)
    (o, xd, yd), res = hlr_outline(s.face(), LIGHT, samples_per_edge=30)
    assert len(res["outline"]) >= 1

    def in_view(p):  # along-light projection coordinates (same for any projection plane)
        return np.c_[(p - o) @ xd, (p - o) @ yd, np.zeros(len(p))]

    mine = [in_view(c) for c in sh.silhouettes]
    for pl in res["outline"]:
        d = np.minimum.reduce([segment_distances(np.c_[pl, np.zeros(len(pl))], m) for m in mine])
        assert d.max() < 1e-3
    # the extent of all projected curves equals HLR's (visible + hidden edges); the outline
    # lies within it
    hl = np.concatenate(res["outline"] + res["sharp"])
    ours = np.concatenate([in_view(c) for c in sh.boundary + sh.silhouettes])[:, :2]
    np.testing.assert_allclose(ours.min(0), hl.min(0), atol=1e-3)
    np.testing.assert_allclose(ours.max(0), hl.max(0), atol=1e-3)
    outline = np.concatenate([in_view(c) for c in sh.outline])[:, :2]
    assert np.all(outline.min(0) >= hl.min(0) - 1e-3) and np.all(outline.max(0) <= hl.max(0) + 1e-3)


@pytest.mark.parametrize(
    "args, match",
    [
        (((0, 0, 0), PLANE), "light_direction"),
        (((np.nan, 0, -1), PLANE), "light_direction"),
        (((1, 0, 0), ((0, 0, 0), (0, 0, 1))), "light_direction: parallel"),
        (((0, 0, -1), ((0, 0, 0), (0, 0, 0))), "plane normal"),
        (((0, 0, -1), "floor"), "plane"),
    ],
)
def test_bad_shadow_input(args, match):
    with pytest.raises(sm.SurfmodError, match=match):
        sm.shadow(sm.plane((0, 0, 1), (1, 0, 1), (0, 1, 1)), *args)
    with pytest.raises(sm.SurfmodError, match="obj"):
        sm.shadow("obj", (0, 0, -1), PLANE)
