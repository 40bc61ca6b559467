"""The NumPy seeding of closest-point projection (ops/nearest.py) against the compiled
branch and bound (ops/seeding.py), and projections that do not depend on which ran."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import fresh_python

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.ops import closest, nearest
from surfmod.ops.seeding import seed_kernel


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
    e, gram, cross, diam = nearest.triangle_tables(g)
    n_basins = max(2, seeds // 2)
    expected = np.empty((len(points), seeds + n_basins, 2))
    seed_kernel(points, np.ascontiguousarray(g), np.ascontiguousarray(us), np.ascontiguousarray(vs), e, gram, cross,
                diam, nearest.row_diameters(diam), seeds, n_basins, expected)
    got = nearest.seed_starts(points, us, vs, g, e, gram, cross, seeds, n_basins)
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
