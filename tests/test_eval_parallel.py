"""The multi-threaded kernels (surfmod/eval/parallel.py) give the single-threaded results
bit for bit, on every path: grid positions (degree <= 3 and above, several row blocks,
several v-blocks), grid partials, scattered positions (basis kernel and per-span
patches), scattered partials; and the thread setting (surfmod/eval/threads.py)."""

from __future__ import annotations

import numba
import numpy as np
import pytest

import surfmod as sm
from surfmod.eval import local, parallel, threads


# the compiled kernels for every call, however small (conftest.compiled_kernels)
pytestmark = pytest.mark.usefixtures("compiled_kernels")

needs_two = pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba may start one thread only")


def _surface(n, m, p, q, rational, seed=0):
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 8, m), indexing="ij")
    net = np.stack([x, y, rng.uniform(-1, 1, (n, m))], axis=-1)

    def knots(k, d):
        # non-uniform spans within 4x of each other (patches.MAX_SPAN_RATIO keeps nets whose
        # spans differ more off the patch path, which these tests run)
        spans = rng.uniform(1, 4, k - d)
        inner = np.cumsum(spans)[:-1] / spans.sum()
        if k - d - 1 >= 2 * d:
            inner[1 : 1 + d] = inner[1]  # an interior knot of multiplicity d
        return np.concatenate([np.zeros(d + 1), np.sort(inner), np.ones(d + 1)])

    w = 10.0 ** rng.uniform(-1, 1, (n, m)) if rational else None
    return sm.BSplineSurface(net, (p, q), (knots(n, p), knots(m, q)), w)


def _both(fn, monkeypatch):
    """``fn()`` on one thread, then on two threads (work of any size goes parallel)."""
    with threads.limit(1):
        serial = fn()
    monkeypatch.setattr(threads, "PARALLEL_MIN_POINTS", 1)
    with threads.limit(2):
        assert threads.threads_for(10) == 2
        threaded = fn()
    return serial, threaded


@needs_two
def test_parallel_far_net_equals_serial_bit_for_bit(monkeypatch):
    """A net far from the origin is evaluated about its centre, which the kernels add back
    to the positions as they store them (local.prepare): grids, scattered points through
    the patches and through the basis kernel, the same on one thread and on two, and the
    same surface as the net at home moved."""
    s = _surface(30, 20, 3, 3, True, seed=4)
    far = sm.BSplineSurface(s.control_points + 1e4, s.degree, s.knots, s.weights)
    assert far._local_net().cache["centred"].origin is not None
    us, vs = np.linspace(0, 1, 101), np.linspace(0, 1, 700)
    u, v = np.random.default_rng(5).uniform(0, 1, (2, 5000))  # scattered: patches (order <= 2) and basis kernel

    def run(surface):
        return (surface.grid(us, vs), surface.grid_derivatives(us[::3], vs[::3], 2), surface.points(u, v),
                surface.derivatives(u, v, 2), surface.derivatives(u, v, 3))

    serial, threaded = _both(lambda: run(far), monkeypatch)
    assert "patches" in far._local_net().cache["centred"].cache
    home = run(s)
    for k, (got, one, at_home) in enumerate(zip(threaded, serial, home)):
        np.testing.assert_array_equal(got, one)
        if k in (0, 2):  # positions
            np.testing.assert_allclose(one, at_home + 1e4, rtol=0, atol=1e-11)
            continue
        np.testing.assert_allclose(one[..., 0, 0, :], at_home[..., 0, 0, :] + 1e4, rtol=0, atol=1e-11)
        np.testing.assert_allclose(one[..., 1:, :, :], at_home[..., 1:, :, :], rtol=0,
                                   atol=1e-11 * np.abs(at_home).max())  # two roundings of a derivative


@needs_two
@pytest.mark.parametrize("p, q", [(3, 3), (2, 1), (5, 4)])
@pytest.mark.parametrize("rational", [False, True])
def test_parallel_grid_equals_serial_bit_for_bit(p, q, rational, monkeypatch):
    s = _surface(60, 45, p, q, rational, seed=p + q)
    us, vs = np.linspace(0, 1, 301), np.r_[np.linspace(0, 1, 1500), 0.25, 0.0]  # unsorted tail
    monkeypatch.setattr(local, "CHUNK", 256)  # several chunks of v-points
    serial, threaded = _both(lambda: (s.grid(us, vs), s.grid_derivatives(us[::7], vs[::5], 2)), monkeypatch)
    assert parallel.tensor_grid_parallel.signatures  # ran threaded
    np.testing.assert_array_equal(threaded[0], serial[0])
    np.testing.assert_array_equal(threaded[1], serial[1])
    buf = np.empty((us.size, vs.size, 3))
    with threads.limit(2):
        s.grid_into(us, vs, buf)
    np.testing.assert_array_equal(buf, serial[0])


@needs_two
@pytest.mark.parametrize("rational", [False, True])
def test_parallel_scattered_equals_serial_bit_for_bit(rational, monkeypatch):
    rng = np.random.default_rng(3)
    small, high = _surface(12, 10, 3, 3, rational, seed=1), _surface(40, 30, 4, 2, rational, seed=2)
    count = 3 * 4096 + 17  # several chunks and a short last one
    u, v = rng.uniform(0, 1, count), rng.uniform(0, 1, count)
    u[:4], v[:4] = 0.0, 1.0  # domain ends

    def run():
        return small.points(u, v), high.points(u, v), small.derivatives(u, v, 2), high.derivatives(u, v, 3)

    serial, threaded = _both(run, monkeypatch)
    assert "patches" in small._local_net().cache  # the per-span patch path ran
    assert parallel.patch_positions_parallel.signatures and parallel.scattered_positions_parallel.signatures
    assert parallel.patch_derivatives_parallel.signatures  # order 2 on the small net: patches too
    for a, b in zip(serial, threaded):
        np.testing.assert_array_equal(b, a)


def test_thread_setting_caps_and_names_bad_counts(monkeypatch):
    monkeypatch.setattr(threads, "numba_threads", lambda: 8)
    with threads.limit(3):
        assert threads.threads_for(10**6) == 3
        assert threads.threads_for(threads.PARALLEL_MIN_POINTS - 1) == 1  # small work: one thread
    with threads.limit(None):
        assert threads.threads_for(10**6) == 8
    with threads.limit(100):
        assert threads.threads_for(10**6) == 8  # no more than numba may start
    for bad in (0, -2, 1.5, True):
        with pytest.raises(sm.SurfmodError, match="count"):
            threads.set_threads(bad)
    assert sm.set_threads is threads.set_threads  # the public name


def test_numba_thread_count_is_restored(monkeypatch):
    before = numba.get_num_threads()
    s = _surface(12, 10, 3, 3, True)
    monkeypatch.setattr(threads, "PARALLEL_MIN_POINTS", 1)
    with threads.limit(None):
        s.grid(np.linspace(0, 1, 50), np.linspace(0, 1, 50))
    assert numba.get_num_threads() == before


@pytest.mark.parametrize("rational", [False, True])
def test_grid_rows_do_not_depend_on_order_or_blocking(rational, monkeypatch):
    """Shuffled u-points are sorted for the ring and put back; every point's values are
    the same bit for bit, in any order and for any chunk of v-points."""
    s = _surface(120, 50, 3, 3, rational, seed=4)
    us, vs = np.linspace(0, 1, 400), np.linspace(0, 1, 900)
    perm = np.random.default_rng(0).permutation(us.size)
    with threads.limit(1):
        for order in (0, 2):
            ordered = s.grid_derivatives(us, vs, order)
            np.testing.assert_array_equal(s.grid_derivatives(us[perm], vs, order), ordered[perm])
            monkeypatch.setattr(local, "CHUNK", 100)  # nine chunks
            np.testing.assert_array_equal(s.grid_derivatives(us, vs, order), ordered)
            monkeypatch.setattr(local, "CHUNK", 1024)
