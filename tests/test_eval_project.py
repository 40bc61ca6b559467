"""The compiled projection internals (eval/projection_kernel.py) against plain
NumPy: exact nearest triangles by brute force, and the NumPy Newton iteration."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.ops import closest as pj
from surfmod.surface import Surface


def _surface(rational=True):
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.linspace(0, 40, 12), np.linspace(0, 30, 10), indexing="ij")
    net = np.stack([x, y, rng.uniform(-5, 5, (12, 10))], -1)
    w = 10 ** rng.uniform(-0.5, 0.5, (12, 10)) if rational else None
    return sm.BSplineSurface(net, (3, 3), weights=w)


def _points(n, seed=1):
    rng = np.random.default_rng(seed)
    return np.c_[rng.uniform(-5, 45, n), rng.uniform(-5, 35, n), rng.uniform(-12, 12, n)]


def _brute_force_feet(p, g):
    """Clipped-foot squared distances of ``p`` to every triangle of the grid (the
    formula of the seeding, written over all triangles at once)."""
    p00, p10, p11, p01 = g[:-1, :-1], g[1:, :-1], g[1:, 1:], g[:-1, 1:]
    out = []
    for e0, e1 in ((p10 - p00, p11 - p00), (p11 - p00, p01 - p00)):
        d00, d01, d11 = (np.einsum("...d,...d->...", a, b) for a, b in ((e0, e0), (e0, e1), (e1, e1)))
        r = p - p00
        r0, r1 = np.einsum("...d,...d->...", r, e0), np.einsum("...d,...d->...", r, e1)
        det = np.maximum(d00 * d11 - d01**2, 1e-300)
        beta = np.clip((d11 * r0 - d01 * r1) / det, 0, 1)
        gamma = np.clip((d00 * r1 - d01 * r0) / det, 0, 1)
        over = np.maximum(beta + gamma, 1.0)
        foot = p00 + (beta / over)[..., None] * e0 + (gamma / over)[..., None] * e1
        out.append(np.einsum("...d,...d->...", foot - p, foot - p).ravel())
    return np.concatenate(out)


def _foot_of_start(u, v, us, vs, g):
    """The 3-D foot whose barycentric coordinates the start (u, v) carries: locate the
    cell and the triangle in parameter space and apply the same weights to the corners."""
    i = np.clip(np.searchsorted(us, u, side="right") - 1, 0, len(us) - 2)
    j = np.clip(np.searchsorted(vs, v, side="right") - 1, 0, len(vs) - 2)
    a = (u - us[i]) / (us[i + 1] - us[i])
    b = (v - vs[j]) / (vs[j + 1] - vs[j])
    if a >= b:  # triangle (i,j), (i+1,j), (i+1,j+1)
        return g[i, j] + (a - b) * (g[i + 1, j] - g[i, j]) + b * (g[i + 1, j + 1] - g[i, j])
    return g[i, j] + a * (g[i + 1, j + 1] - g[i, j]) + (b - a) * (g[i, j + 1] - g[i, j])


def test_seeds_are_the_exact_nearest_triangles():
    s = _surface()
    us, vs, g = pj.seed_grid(s)
    pts = _points(40)
    starts = pj.seed_starts(pts, us, vs, g, 8)
    assert starts.shape == (40, 12, 2)
    for p, st in zip(pts, starts):
        best = np.sort(_brute_force_feet(p, g))[:8]
        found = np.sort([np.sum((_foot_of_start(u, v, us, vs, g) - p) ** 2) for u, v in st[:8]])
        np.testing.assert_allclose(found, best, rtol=1e-9, atol=1e-9)


def test_seed_distances_match_brute_force():
    """The kernel's top-8 foot distances equal the brute-force 8 smallest."""
    s = _surface(False)
    us, vs, g = pj.seed_grid(s)
    pts = _points(25, seed=4)
    e, gram, cross, diam = pj.triangle_tables(g)
    for p in pts:
        feet = _brute_force_feet(p, g)
        # feet from the kernel's chosen (u, v) are not recoverable in 3-D exactly, so
        # recompute the foot distances of the tables' triangles and compare the sets
        d_tables = []
        for t in range(2):
            a0, a1 = e[..., 2 * t, :], e[..., 2 * t + 1, :]
            r = p - g[:-1, :-1]
            r0, r1 = np.einsum("...d,...d->...", r, a0), np.einsum("...d,...d->...", r, a1)
            d00, d11, d01 = gram[..., 2 * t], gram[..., 2 * t + 1], cross[..., t]
            det = np.maximum(d00 * d11 - d01**2, 1e-300)
            beta = np.clip((d11 * r0 - d01 * r1) / det, 0, 1)
            gamma = np.clip((d00 * r1 - d01 * r0) / det, 0, 1)
            over = np.maximum(beta + gamma, 1.0)
            foot = g[:-1, :-1] + (beta / over)[..., None] * a0 + (gamma / over)[..., None] * a1
            d_tables.append(np.einsum("...d,...d->...", foot - p, foot - p).ravel())
        np.testing.assert_allclose(np.sort(np.concatenate(d_tables)), np.sort(feet), rtol=1e-12, atol=1e-12)
    assert diam.shape == g[:-1, :-1].shape[:2] and np.all(diam > 0)


class _Generic(Surface):
    """The same surface seen only through the generic protocol: the NumPy Newton path."""

    def __init__(self, s):
        self.s = s

    @property
    def domain(self):
        return self.s.domain

    def _derivatives(self, u, v, order):
        return self.s._derivatives(u, v, order)

    def geom(self):
        return self.s.geom()

    def transformed(self, matrix):
        return _Generic(self.s.transformed(matrix))


@pytest.mark.parametrize("rational", [False, True])
def test_compiled_newton_matches_numpy_newton(rational):
    s = _surface(rational)
    pts = _points(300, seed=2)
    fast = sm.project(pts, s)
    slow = sm.project(pts, _Generic(s))
    # the same iteration; the derivatives round differently (quotient rule grouping), so
    # a start creeping along a flat boundary minimum may stop a line-search step apart
    np.testing.assert_allclose(fast.distance, slow.distance, rtol=2e-8)
    same = np.abs(fast.distance - slow.distance) <= 1e-12 * np.maximum(1.0, slow.distance)
    assert same.mean() > 0.95
    # (on such flat minima the foot itself is ill-determined: only the distance is compared)
    np.testing.assert_allclose(np.linalg.norm(fast.point - pts, axis=1), fast.distance, rtol=1e-12)
    np.testing.assert_allclose(s.points(fast.u, fast.v), fast.point, rtol=0, atol=1e-12)
