"""Every twin gives the same answers: ``name`` (NumPy, module ``X.py``), ``name_compiled``
(numba, one thread, module ``X_compiled.py``) and ``name_parallel`` (numba ``prange``,
:mod:`surfmod.eval.parallel`), on random input.

- the lattice bounds of the grid mesher, ``meshing/gridbounds.py`` and
  ``gridbounds_compiled.py``: bit for bit, on real lattices and on hostile ones
  (degenerate cells, a pole, NaN), and meshes do not depend on which ran;
- scattered evaluation, ``eval/scattered.py`` and ``scattered_compiled.py``, and the
  grid, ``eval/tensor_grid.py`` and ``tensor_grid_compiled.py``: to 1e-12 of each
  partial's magnitude (the kernels multiply by reciprocal knot differences where the
  NumPy basis divides);
- the ``_parallel`` variants against their ``_compiled`` twins: bit for bit.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

import surfmod as sm
from surfmod.eval import kernels, local, parallel, patches, threads
from surfmod.eval.scattered import scattered
from surfmod.eval.scattered_compiled import scattered_compiled, scattered_positions_compiled
from surfmod.eval.tensor_grid import tensor_grid
from surfmod.gallery.synthetic import wavy_net
from surfmod.meshing import gridbounds, gridmesh
from surfmod.meshing.gridbounds_compiled import cell_maxima_compiled, diagonals_compiled, estimates_compiled

#: agreement of the NumPy and compiled evaluation twins, relative to each partial's magnitude
REL = 1e-12


def _lattice(s, ncu, ncv, K=gridmesh.K):
    us = np.linspace(*s.domain[0], ncu * K + 1)
    vs = np.linspace(*s.domain[1], ncv * K + 1)
    return np.ascontiguousarray(s.grid(us, vs))


def _compare(S, K, kmax):
    ncu, ncv = (S.shape[0] - 1) // K, (S.shape[1] - 1) // K
    diag = np.zeros((ncu, ncv), bool)
    diagonals_compiled(S, K, diag)
    np.testing.assert_array_equal(gridbounds.diagonals(S, K, (ncu, ncv)), diag)
    est, Q = np.empty(S.shape[:2]), np.empty_like(S)
    estimates_compiled(S, K, diag, kmax, est, Q)
    est2, Q2 = gridbounds.estimates(S, K, diag, kmax)
    np.testing.assert_array_equal(Q2, Q)
    np.testing.assert_array_equal(est2, est)
    parts = [np.full((ncu, ncv), -1.0) for _ in range(3)]
    cell_maxima_compiled(est, K, *parts)
    for mine, theirs in zip(gridbounds.cell_maxima(est, K, (ncu, ncv)), parts):
        np.testing.assert_array_equal(mine, theirs)


@pytest.mark.parametrize("surface", [
    sm.BSplineSurface(wavy_net(8, 8), (3, 3)),
    sm.torus(3.0, 1.0),
    sm.sphere(2.0),  # poles: degenerate tangent planes
])
@pytest.mark.parametrize("K", [2, gridmesh.K])
def test_numpy_bounds_equal_the_compiled_loops(surface, K):
    _compare(_lattice(surface, 7, 5, K), K, 0.8)


def test_numpy_bounds_equal_the_compiled_loops_on_hostile_lattices():
    rng = np.random.default_rng(2)
    K = gridmesh.K
    S = rng.normal(size=(3 * K + 1, 2 * K + 1, 3))
    S[K : 2 * K, :K] = 0.0  # collapsed cells
    S[1, 1] = np.nan
    S[-1, -1] = np.inf
    with np.errstate(invalid="ignore", over="ignore"):
        _compare(S, K, 3.0)


def test_mesh_is_the_same_whichever_path_bounds_it(monkeypatch):
    s = sm.BSplineSurface(wavy_net(8, 8), (3, 3))
    small = sm.tessellate(s, 0.05)
    monkeypatch.setattr(gridmesh, "COMPILED_LATTICE", 0)
    compiled = sm.tessellate(s, 0.05)
    np.testing.assert_array_equal(small.vertices, compiled.vertices)
    np.testing.assert_array_equal(small.faces, compiled.faces)


# -- evaluation twins ------------------------------------------------------------------------
def _net(seed, p, q, rational, far=False):
    """A random net: random poles, clamped knots with random spans and an interior knot of
    multiplicity up to the degree, random weights over two decades."""
    rng = np.random.default_rng(seed)
    n, m = p + 1 + int(rng.integers(0, 9)), q + 1 + int(rng.integers(0, 9))

    def knots(count, degree):
        inner = np.sort(rng.uniform(0, 1, count - degree - 1))
        if inner.size > degree:
            inner[1 : degree + 1] = inner[1]
        return np.concatenate([np.zeros(degree + 1), np.sort(inner), np.ones(degree + 1)])

    pts = rng.normal(size=(n, m, 3)) + (1e4 if far else 0.0)
    w = 10.0 ** rng.uniform(-1, 1, (n, m)) if rational else None
    h = np.concatenate([pts * w[..., None], w[..., None]], axis=-1) if rational else pts
    return local.prepare(knots(n, p), p, knots(m, q), q, h, pts, w), rng


def _close(got, want):
    """``got`` within :data:`REL` of the largest magnitude of each partial of ``want``."""
    scale = np.abs(want).reshape(-1, *want.shape[-3:]).max(axis=(0, 3), keepdims=True)
    err = np.abs(got - want).reshape(-1, *want.shape[-3:]).max(axis=(0, 3), keepdims=True)
    assert np.all(err <= REL * scale), (err / scale).max()


CASES = [(seed, p, q, rational) for seed, (p, q) in enumerate([(1, 1), (2, 3), (3, 3), (5, 2), (4, 6)])
         for rational in (False, True)]


@pytest.mark.parametrize("seed, p, q, rational", CASES)
def test_scattered_and_scattered_compiled_agree(seed, p, q, rational):
    net, rng = _net(seed, p, q, rational)
    u, v = rng.uniform(0, 1, 700), rng.uniform(0, 1, 700)
    u[:3], v[:3] = (net.knots_u[p + 1], 1.0, 0.0), (0.0, 1.0, net.knots_v[q + 1])  # knots, domain ends
    for order in range(4):
        want = scattered(*net[:4], net.ctrl, net.rational, u, v, order)
        got = np.empty(want.shape)
        scattered_compiled(*net[:5], u, v, order, net.rational, kernels.binomials(order), *net[6:10], got)
        _close(got, want)
        if order == 0:
            positions = np.empty((u.size, 3))
            scattered_positions_compiled(*net[:5], u, v, net.rational, *net[6:10], positions)
            _close(positions[:, None, None], want)


@pytest.mark.parametrize("seed, p, q, rational", CASES)
def test_tensor_grid_and_tensor_grid_compiled_agree(seed, p, q, rational):
    net, rng = _net(seed + 20, p, q, rational)
    us, vs = np.sort(rng.uniform(0, 1, 37)), rng.uniform(0, 1, 53)
    for order in (0, 1, 2):
        want = tensor_grid(*net[:4], net.ctrl, net.rational, us, vs, order)
        got = np.empty(want.shape)
        with threads.limit(1):
            local._grid_sorted(net, us, vs, order, got)
        _close(got, want)


@pytest.mark.parametrize("rational", [False, True])
def test_parallel_variants_equal_their_compiled_twins(rational):
    """The ``_parallel`` kernels, called directly on whatever threads numba has, give their
    ``_compiled`` twins' values bit for bit (several chunks and a short last one)."""
    net, rng = _net(7, 3, 3, rational, far=True)
    net = local._centred(net)
    count = 2 * kernels.SCATTER_CHUNK + 17
    u, v = rng.uniform(0, 1, count), rng.uniform(0, 1, count)
    pairs = [(scattered_positions_compiled, parallel.scattered_positions_parallel, (u.size, 3),
              (*net[:5], u, v, net.rational, *net[6:10])),
             (scattered_compiled, parallel.scattered_parallel, (u.size, 3, 3, 3),
              (*net[:5], u, v, 2, net.rational, kernels.binomials(2), *net[6:10]))]
    table = patches.build_table(net)
    for compiled, threaded, order in ((patches.patch_positions_compiled, parallel.patch_positions_parallel, 0),
                                      (patches.patch_derivatives_compiled, parallel.patch_derivatives_parallel, 2)):
        shape = (u.size, 3) if order == 0 else (u.size, 3, 3, 3)
        pairs.append((compiled, threaded, shape, patches.arguments(net, table, u, v, np.empty(shape))[:-1]))
    for compiled, threaded, shape, args in pairs:
        one, many = np.empty(shape), np.empty(shape)
        compiled(*args, one, net.origin)
        threaded(*args, many, net.origin)
        np.testing.assert_array_equal(many, one)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba may start one thread only")
def test_tensor_grid_parallel_equals_its_compiled_twin(monkeypatch):
    net, rng = _net(9, 3, 2, True)
    us, vs = np.sort(rng.uniform(0, 1, 150)), rng.uniform(0, 1, 90)
    one, many = np.empty((us.size, vs.size, 3, 3, 3)), np.empty((us.size, vs.size, 3, 3, 3))
    with threads.limit(1):
        local._grid_sorted(net, us, vs, 2, one)
    monkeypatch.setattr(threads, "PARALLEL_MIN_POINTS", 1)
    with threads.limit(2):
        local._grid_sorted(net, us, vs, 2, many)
    assert parallel.tensor_grid_parallel.signatures
    np.testing.assert_array_equal(many, one)
