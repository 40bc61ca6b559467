"""The compiled grid (surfmod/eval/tensor_grid_compiled.py), its row stage (surfmod/eval/row_stage.py)
and its paired position stage (surfmod/eval/position_stage.py): runs of v-points in
consecutive spans go through vector loops over the net's coordinate planes and give the
one-point-at-a-time sums bit for bit, at every degree and order; grids on nets with about
one point a span (where those loops run) agree with the scattered kernel, the textbook and
OCCT; the values do not depend on the chunks of the ring; positions and partials of every
order are one compiled function."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from conftest import fresh_python
import reference as ref

import surfmod as sm
from surfmod.eval import local, row_stage, threads
from surfmod.eval.scattered import basis_at
from surfmod.occ.sample import surface_d2


# the compiled kernels for every call, however small (conftest.compiled_kernels)
pytestmark = pytest.mark.usefixtures("compiled_kernels")


def _uniform_surface(n, m, p, q, rational, seed=0):
    """A net with uniform knots (so evenly spaced parameters fall one a span) and a
    wavy height."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 8, m), indexing="ij")
    net = np.stack([x, y, rng.uniform(-1, 1, (n, m))], axis=-1)
    w = 10.0 ** rng.uniform(-1, 1, (n, m)) if rational else None
    return sm.BSplineSurface(net, (p, q), weights=w)


def _reference_runs(sv, min_run):
    """Point ``b`` is in a vector run iff it lies in a maximal stretch of spans one apart
    of at least ``min_run`` points (stretches taken left to right)."""
    vector = np.zeros(sv.size, dtype=bool)
    b = 0
    while b < sv.size:
        e = b + 1
        while e < sv.size and sv[e] - sv[e - 1] == 1:
            e += 1
        if e - b >= min_run:
            vector[b:e] = True
            b = e
        else:
            b += 1
    return vector


@pytest.mark.parametrize("seed", range(6))
def test_runs_cover_the_points_as_the_reference_splits_them(seed):
    rng = np.random.default_rng(seed)
    steps = rng.choice([0, 1, 1, 1, 2], size=400, p=[0.1, 0.3, 0.3, 0.25, 0.05])
    sv = np.r_[3, 3 + np.cumsum(steps)].astype(np.int64)
    if seed % 2:
        sv = rng.permutation(sv)  # unsorted spans: short stretches only
    for min_run in (1, 4, row_stage.MIN_RUN):
        starts, kinds = row_stage.runs(sv, min_run)
        assert starts[0] == 0 and starts[-1] == sv.size and np.all(np.diff(starts) > 0)
        assert not np.any((kinds[1:] == row_stage.SCALAR) & (kinds[:-1] == row_stage.SCALAR))
        vector = np.zeros(sv.size, dtype=bool)
        for b0, b1, kind in zip(starts[:-1], starts[1:], kinds):
            if kind == row_stage.NEXT_SPAN:
                assert b1 - b0 >= min_run and np.all(np.diff(sv[b0:b1]) == 1)
                vector[b0:b1] = True
        np.testing.assert_array_equal(vector, _reference_runs(sv, min_run))


@pytest.mark.parametrize("q", range(1, 7))
@pytest.mark.parametrize("order", [0, 1, 2])
@pytest.mark.parametrize("rational", [False, True])
def test_vector_row_stage_equals_the_scalar_one_bit_for_bit(q, order, rational):
    """Runs of consecutive spans, runs in one span and odd points, at every v-degree and
    derivative order: the vector loops give the scalar loop's sums exactly."""
    s = _uniform_surface(30, 140, 3, q, rational, seed=q)
    net = s._local_net()
    (v0, v1), m = s.domain[1], net.ctrl.shape[1]
    spans = m - q  # uniform knots: span k is [k, k+1] / spans
    rng = np.random.default_rng(q)
    vs = np.r_[(np.arange(3, 3 + 2 * row_stage.MIN_RUN) + 0.5) / spans, np.full(9, 0.5), rng.uniform(v0, v1, 20),
               v1, (np.arange(60, 60 + row_stage.MIN_RUN) + 0.25) / spans]
    sv, bv = basis_at(net.knots_v, q, m, vs, order)
    starts, kinds = row_stage.runs(sv)
    assert np.any(kinds == row_stage.NEXT_SPAN) and np.any(kinds == row_stage.SCALAR)
    rows = np.array([0, 4, 5, 6, 17, 29], dtype=np.int64)
    dim = 4 if rational else 3
    scalar = np.full((rows.size, order + 1, dim, vs.size), np.nan)
    vector = np.full_like(scalar, np.nan)
    for plan, dst in ((local._scalar_plan(net, sv, bv), scalar),
                      ((np.ascontiguousarray(bv.transpose(1, 2, 0)), row_stage.net_planes(net.ctrl), starts, kinds),
                       vector)):
        bplan, planes, run_starts, run_kinds = plan
        for k, r in enumerate(rows):
            row_stage.contract_row(bv, bplan, sv, q, net.ctrl[r], planes[r], dim, dst[k].reshape(-1), 0, vs.size,
                                   run_starts, run_kinds, 0, vs.size)
    np.testing.assert_array_equal(vector, scalar)
    # and the sums are the textbook's: net rows contracted with the v-basis
    dense = np.zeros((vs.size, order + 1, m))
    for b in range(vs.size):
        dense[b, :, sv[b] - q : sv[b] + 1] = bv[b]
    expected = np.einsum("blj,rjd->rldb", dense, net.ctrl[rows][..., :dim])
    np.testing.assert_allclose(vector, expected, rtol=1e-14, atol=1e-13 * np.abs(expected).max())


@pytest.mark.parametrize("p, q", [(3, 3), (2, 3), (3, 2), (1, 4)])
@pytest.mark.parametrize("rational", [False, True])
def test_grid_on_a_big_net_through_the_vector_paths(p, q, rational, monkeypatch):
    """About one point a span in both directions: the row stage runs its vector loops
    (the net's coordinate planes get built), cubic u-points go in shifted pairs; the
    result equals the one-point-at-a-time path bit for bit and the scattered kernel,
    the textbook and OCCT to 1e-13."""
    s = _uniform_surface(150, 130, p, q, rational, seed=p + 3 * q)
    (u0, u1), (v0, v1) = s.domain
    us, vs = np.linspace(u0, u1, 149), np.linspace(v0, v1, 131)
    grid = s.grid(us, vs)
    ders = s.grid_derivatives(us[::3], vs, 2)
    assert "planes" in s._local_net().cache
    monkeypatch.setattr(local, "_row_stage_plan", lambda net, sv, bv, rows: local._scalar_plan(net, sv, bv))
    np.testing.assert_array_equal(grid, s.grid(us, vs))
    np.testing.assert_array_equal(ders, s.grid_derivatives(us[::3], vs, 2))
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    scale = np.abs(s.control_points).max()
    np.testing.assert_allclose(grid.reshape(-1, 3), s.points(uu, vv), rtol=0, atol=1e-13 * scale)
    sub = np.s_[::7, ::9]
    uu, vv = (a[sub].ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    (pp, qq), (ku, kv) = s.degree, s.knots
    expected = np.array([ref.bspline_surface_derivatives(s.control_points, pp, qq, ku, kv, u, v, 0, s.weights)
                         for u, v in zip(uu, vv)])[:, 0, 0]
    np.testing.assert_allclose(grid[sub].reshape(-1, 3), expected, rtol=0, atol=1e-13 * scale)
    occ = surface_d2(s.geom(), uu, vv)[:, 0, 0]
    np.testing.assert_allclose(grid[sub].reshape(-1, 3), occ, rtol=0, atol=1e-13 * scale)


def test_a_few_rows_of_a_big_net_skip_the_planes():
    """Three u-points read twelve rows of a 400-row net: no copy of the net is made."""
    s = _uniform_surface(400, 300, 3, 3, True)
    s.grid([0.1, 0.5, 0.9], np.linspace(0, 1, 299))
    assert "planes" not in s._local_net().cache


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba may start one thread only")
@pytest.mark.parametrize("rational", [False, True])
def test_parallel_vector_paths_equal_serial_bit_for_bit(rational, monkeypatch):
    s = _uniform_surface(200, 180, 3, 3, rational, seed=5)
    us, vs = np.linspace(0, 1, 401), np.linspace(0, 1, 180)
    monkeypatch.setattr(local, "GRID_MIN_BLOCK", 3)  # many blocks of u-points, a ring each
    with threads.limit(1):
        serial = s.grid(us, vs), s.grid_derivatives(us[::5], vs, 2)
    monkeypatch.setattr(threads, "PARALLEL_MIN_POINTS", 1)
    with threads.limit(2):
        threaded = s.grid(us, vs), s.grid_derivatives(us[::5], vs, 2)
    np.testing.assert_array_equal(threaded[0], serial[0])
    np.testing.assert_array_equal(threaded[1], serial[1])


@pytest.mark.parametrize("rational", [False, True])
def test_the_ring_over_several_v_chunks(rational, monkeypatch):
    """More v-points than a chunk of the ring, u-points skipping spans (rows no u-point
    reads are not contracted), pairs and single points, unsorted u-points: the same bits
    as with one chunk and as the one-point-at-a-time row stage, and the points of the
    scattered kernel; partials to orders 1 and 3 likewise."""
    s = _uniform_surface(90, 2200, 3, 3, rational, seed=11)
    us = np.sort(np.r_[np.linspace(0, 1, 60), np.linspace(0.2, 0.3, 25), 0.5, 0.5])
    spans = 2200 - 3
    vs = np.sort(np.r_[(np.arange(spans) + 0.5) / spans, 0.25, 0.25, 1.0])  # one a span, and a few more
    assert 2 * local.CHUNK < vs.size
    _, kinds = row_stage.runs(basis_at(s.knots[1], 3, 700, vs, 0)[0])
    assert np.count_nonzero(kinds == row_stage.NEXT_SPAN) >= 2 and np.any(kinds == row_stage.SCALAR)
    grid = s.grid(us, vs)
    ders = {order: s.grid_derivatives(us[::4], vs, order) for order in (1, 3)}
    assert "planes" in s._local_net().cache
    monkeypatch.setattr(local, "CHUNK", 1 << 20)
    np.testing.assert_array_equal(grid, s.grid(us, vs))
    for order, d in ders.items():
        np.testing.assert_array_equal(d, s.grid_derivatives(us[::4], vs, order))
    monkeypatch.setattr(local, "_row_stage_plan", lambda net, sv, bv, rows: local._scalar_plan(net, sv, bv))
    np.testing.assert_array_equal(grid, s.grid(us, vs))
    perm = np.random.default_rng(2).permutation(us.size)
    np.testing.assert_array_equal(s.grid(us[perm], vs), grid[perm])
    uu, vv = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
    np.testing.assert_allclose(grid.reshape(-1, 3), s.points(uu, vv), rtol=0,
                               atol=1e-13 * np.abs(s.control_points).max())
    uu, vv = (a.ravel() for a in np.meshgrid(us[::4], vs[::37], indexing="ij"))
    for order, d in ders.items():
        np.testing.assert_allclose(d[:, ::37].reshape(uu.size, -1), s.derivatives(uu, vv, order).reshape(uu.size, -1),
                                   rtol=1e-12, atol=1e-10 * np.abs(d).max())


def test_positions_and_partials_are_one_compiled_grid():
    """One compiled path for grids: positions and partials of every order, polynomial and
    rational, on small and big nets, in a fresh process, compile ``tensor_grid_compiled``
    once (one signature)."""
    script = (
        "import numpy as np, surfmod as sm\n"
        "from surfmod.gallery.synthetic import wavy_net\n"
        "from surfmod.eval import tensor_grid_compiled, threads\n"
        "threads.set_threads(1)\n"
        "u = np.linspace(0, 1, 1000)\n"
        "for n, w in ((20, None), (300, np.full((300, 300), 2.0))):\n"
        "    s = sm.BSplineSurface(wavy_net(n, n), (3, 3), weights=w)\n"
        "    s.grid(u, u); s.grid_derivatives(u, u[:500], 1); s.grid_derivatives(u, u[:400], 2)\n"
        "print(len(tensor_grid_compiled.tensor_grid_compiled.signatures))\n"
    )
    assert fresh_python(script) == ["1"]


def test_the_meshers_mid_sized_grids_stay_in_numpy():
    """Grids below ``COMPILED_GRID`` partials (the structured mesher's 103 x 633 grid to
    order 2, the superellipsoid's 406 x 813 positions) are evaluated in NumPy: in a fresh
    process they import neither the grid kernels nor numba, so a first ``surfmod gallery``
    compiles no grid stage."""
    script = (
        "import sys, numpy as np, surfmod as sm\n"
        "from surfmod.gallery.synthetic import wavy_net\n"
        "from surfmod.eval.local import COMPILED_GRID\n"
        "assert 103 * 633 * 9 < COMPILED_GRID\n"
        "s = sm.BSplineSurface(wavy_net(8, 8), (3, 3))\n"
        "s.grid_derivatives(np.linspace(0, 1, 103), np.linspace(0, 1, 633), 2)\n"
        "s.grid(np.linspace(0, 1, 406), np.linspace(0, 1, 813))\n"
        "print(int('surfmod.eval.tensor_grid_compiled' in sys.modules), int('numba' in sys.modules))\n"
    )
    assert fresh_python(script) == ["0", "0"]
