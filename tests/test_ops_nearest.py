"""The NumPy twins of closest-point projection (surfmod.ops.closest) against their compiled
twins (surfmod.eval.projection_kernel, ``<name>_compiled``): the seeds, the Newton
iteration, and projections that do not depend on which ran."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import fresh_python

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.eval.kernels import binomials
from surfmod.eval.projection_kernel import grid_seeds_compiled, newton_in_boxes_compiled
from surfmod.ops import closest


@pytest.mark.parametrize("surface", [
    sm.BSplineSurface(wavy_net(8, 8), (3, 3)),
    sm.torus(3.0, 1.0),
    sm.BSplineSurface(wavy_net(5, 4), (3, 2), weights=np.linspace(0.5, 2, 20).reshape(5, 4)),
])
@pytest.mark.parametrize("seeds", [1, 8])
def test_numpy_seeds_equal_the_compiled_kernel(surface, seeds):
    rng = np.random.default_rng(4)
    points = rng.uniform(-3, 11, (300, 3))
    us, vs, g = closest.seed_grid(surface)
    e, gram, cross, diam = closest.triangle_tables(g)
    n_basins = max(2, seeds // 2)
    expected = np.empty((len(points), seeds + n_basins, 2))
    grid_seeds_compiled(points, np.ascontiguousarray(g), np.ascontiguousarray(us), np.ascontiguousarray(vs), e, gram,
                        cross, diam, closest.row_diameters(diam), seeds, n_basins, expected)
    got = closest.grid_seeds(points, us, vs, g, e, gram, cross, seeds, n_basins)
    if isinstance(surface, sm.BSplineSurface):  # no seam
        np.testing.assert_array_equal(got, expected)
    # a periodic grid repeats its seam: equally near feet there may come in another order,
    # the same points of the surface
    at = [np.sort(surface.points(x[..., 0], x[..., 1]).round(9).view("f8,f8,f8"), axis=1) for x in (got, expected)]
    np.testing.assert_array_equal(at[0], at[1])


def test_projection_is_the_same_whichever_path_ran(monkeypatch):
    s = sm.BSplineSurface(wavy_net(8, 8), (3, 3))
    rng = np.random.default_rng(1)
    pts = np.c_[rng.uniform(0, 10, 40), rng.uniform(0, 8, 40), rng.uniform(-1, 2, 40)]
    small = sm.project(pts, s, progress=False)
    monkeypatch.setattr(closest, "COMPILED_SEED_PAIRS", 0)
    monkeypatch.setattr(closest, "COMPILED_NEWTON_STARTS", 0)
    compiled = sm.project(pts, s, progress=False)
    np.testing.assert_allclose(small.distance, compiled.distance, rtol=0, atol=1e-12)
    np.testing.assert_allclose(small.point, compiled.point, rtol=0, atol=1e-10)


def test_a_small_projection_takes_the_numpy_paths():
    """500 points on a 8x8 B-spline (the cold-start row of ``python -m benchmarks eval``)
    are seeded and refined in NumPy: a fresh process never imports numba, so the first
    projection of a session does not wait for kernels to load or compile."""
    script = (
        "import sys, numpy as np, surfmod as sm\n"
        "from surfmod.gallery.synthetic import wavy_net\n"
        "rng = np.random.default_rng(1)\n"
        "pts = np.c_[rng.uniform(0, 10, 500), rng.uniform(0, 8, 500), rng.uniform(-1, 2, 500)]\n"
        "r = sm.project(pts, sm.BSplineSurface(wavy_net(8, 8), (3, 3)), progress=False)\n"
        "print(len(r.distance), 'numba' in sys.modules)\n"
    )
    assert fresh_python(script) == ["500", "False"]


@pytest.mark.parametrize("rational", [False, True])
def test_numpy_newton_equals_the_compiled_kernel(rational):
    """``newton_in_boxes`` and ``newton_in_boxes_compiled`` from the same starts in the
    same boxes (pieces of a crease at u = 0.5) reach the same points."""
    weights = np.linspace(0.5, 2, 64).reshape(8, 8) if rational else None
    s = sm.BSplineSurface(wavy_net(8, 8), (3, 3), weights=weights)
    rng = np.random.default_rng(5)
    n = 400
    points = np.c_[rng.uniform(-2, 12, n), rng.uniform(-2, 10, n), rng.uniform(-2, 3, n)]
    (u0, u1), (v0, v1) = s.domain
    mid = 0.5 * (u0 + u1)
    low = rng.random(n) < 0.5
    box = (np.where(low, u0, mid), np.where(low, mid, u1), np.full(n, v0), np.full(n, v1))
    u = np.where(low, rng.uniform(u0, mid, n), rng.uniform(mid, u1, n))
    v = rng.uniform(v0, v1, n)
    expected = closest.newton_in_boxes(s, points, u, v, box, 60)
    net = s._local_net()
    got = u.copy(), v.copy()
    newton_in_boxes_compiled(net.knots_u, net.p, net.knots_v, net.q, net.ctrl, net.rational, net.inv_u, net.inv_v,
                             net.bucket_u, net.bucket_v, binomials(2), binomials(0), points, *got, *box,
                             float(u1 - u0), float(v1 - v0), 60)
    assert all(np.all((x >= lo) & (x <= hi)) for x, lo, hi in ((got[0], box[0], box[1]), (got[1], box[2], box[3])))
    dist = [np.linalg.norm(s.points(*x) - points, axis=1) for x in (expected, got)]
    # the same iteration; the derivatives round differently (quotient rule grouping), so a
    # start creeping along a flat minimum may stop a line-search step apart
    np.testing.assert_allclose(dist[1], dist[0], rtol=2e-8, atol=1e-12)
    same = np.maximum(np.abs(got[0] - expected[0]), np.abs(got[1] - expected[1])) <= 1e-9
    assert same.mean() > 0.95
