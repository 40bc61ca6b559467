"""The grid's stage for partials to order 2 (surfmod/eval/partials_stage.py): equal to
the general stage to rounding for every degree, chunk tail, alignment and v-offset; and
through the public API on grids of one and two v-blocks."""

import numpy as np
import pytest

import surfmod as sm
from surfmod.eval import local
from surfmod.eval.grid_kernels import grid_derivatives
from surfmod.eval.kernels import binomials
from surfmod.eval.partials_stage import CHUNK, order2_block
from surfmod.gallery.synthetic import wavy_net


def _table(rng, p, rational, nu, nv):
    """A random row table, u-basis and first rows, shaped as the grid's first stage
    makes them; weights and their combinations stay well away from 0."""
    rows = p + 4
    w = rng.uniform(0.5, 1.5, (rows, 3, 4 if rational else 3, nv))
    bu = rng.uniform(0.0, 1.0, (nu, 3, p + 1))
    first = rng.integers(0, rows - p, nu)
    return w, bu, first


def _assert_within(got, ref, rel):
    """``got`` equals ``ref`` within ``rel`` of each partial's largest size (over the
    points and coordinates)."""
    scale = np.abs(ref).max(axis=(0, 1, 4), keepdims=True)
    worst = (np.abs(got - ref) / scale).max()
    assert worst <= rel, f"off by {worst:.2e} of a partial's size"


def _general(bu, first, p, w, rational, b0, shape):
    out = np.full(shape, np.nan)
    grid_derivatives(bu, first, p, w, rational, binomials(2), b0, out)
    return out


@pytest.mark.parametrize("p", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("nv", [1, 2, CHUNK - 1, CHUNK, 2 * CHUNK + 3])
def test_stage_equals_the_general_path(p, rational, nv):
    rng = np.random.default_rng(100 * p + nv + rational)
    w, bu, first = _table(rng, p, rational, 3, nv)
    for b0 in (0, 1, 2):  # the rows start on, and 8 bytes past, a 16-byte boundary
        shape = (3, nv + b0 + 1, 3, 3, 3)
        expected = _general(bu, first, p, w, rational, b0, shape)
        got = np.full(shape, np.nan)
        order2_block(bu, first, p, w, rational, b0, got)
        # points outside [b0, b0 + nv) are untouched; inside, the general path's values
        # to rounding (fused multiply-adds; a few ulps after the quotient rule's differences)
        assert np.isnan(got[:, :b0]).all() and np.isnan(got[:, b0 + nv:]).all()
        _assert_within(got[:, b0 : b0 + nv], expected[:, b0 : b0 + nv], 5e-14)


def test_an_empty_block_writes_nothing():
    w, bu, first = _table(np.random.default_rng(3), 3, True, 0, 2 * CHUNK)
    out = np.full((2, 2 * CHUNK, 3, 3, 3), np.nan)
    order2_block(bu, first, 3, w, True, 0, out[:0])
    assert np.isnan(out).all()


def test_stage_writes_a_misaligned_array():
    """A caller's array whose rows start 8 bytes past a 16-byte boundary (a view one
    double into a buffer) gets the same values."""
    rng = np.random.default_rng(5)
    w, bu, first = _table(rng, 3, True, 4, 2 * CHUNK + 1)
    buffer = np.full(1 + 4 * w.shape[3] * 27, np.nan)
    shifted = buffer[1:].reshape(4, w.shape[3], 3, 3, 3)
    aligned = np.full(shifted.shape, np.nan)
    order2_block(bu, first, 3, w, True, 0, shifted)
    order2_block(bu, first, 3, w, True, 0, aligned)
    np.testing.assert_array_equal(shifted, aligned)
    assert np.isnan(buffer[0])


@pytest.mark.parametrize("nu, nv", [(300, 300), (90, 1100), (80, 1101)])
def test_a_grid_into_a_callers_array_equals_the_grid_and_scattered_partials(nu, nv):
    """Partials to order 2 of grids of one v-block or two (the second starting at point
    1024; rows of an even or an odd number of points) through the compiled stage: into a
    caller's array they equal ``grid_derivatives`` bit for bit, and the scattered
    kernel's partials (a different algorithm) to 1e-13 of each partial's size."""
    rng = np.random.default_rng(11)
    s = sm.BSplineSurface(wavy_net(9, 8), (3, 2), weights=10 ** rng.uniform(-1, 1, (9, 8)))
    us, vs = np.linspace(0, 1, nu), np.sort(rng.uniform(0, 1, nv))
    assert nu * nv * 9 >= local.COMPILED_GRID  # the compiled stage, not NumPy
    into = s.grid_into(us, vs, np.empty((nu, nv, 3, 3, 3)), order=2)
    np.testing.assert_array_equal(into, s.grid_derivatives(us, vs, 2))
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    scattered = s.derivatives(uu.ravel(), vv.ravel(), 2).reshape(into.shape)
    _assert_within(into, scattered, 1e-13)
