"""Compiled (numba) kernels for grids ``us x vs`` with local support, in two stages:
the net rows the u-points need contracted with the v-basis once (:func:`grid_rows`),
then p+1 rows combined per u-point with the v-points on the vector axis
(:func:`grid_positions`, :func:`grid_derivatives`), block by block of u-points
(:func:`positions_grid`, :func:`partials_grid`).  Conventions as in
:mod:`surfmod.eval.kernels`; the multi-threaded variants are in :mod:`surfmod.eval.parallel`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, uint64

from . import sliding
from .kernels import U1, U2, U3, quotient_planes
from .partials_stage import order2_block
from .position_stage import positions_low_degree
from .row_stage import contract_rows, row_points


@njit(cache=True, error_model="numpy")
def positions_grid(bv, sv, q, ctrl, dim, bu, p, rational, b0, out, scratch, starts, rows, row_starts, first, vruns):
    """The grid of positions ``us x vs[b0:b0+n_v]`` into ``out`` (point-major ``(n_u, N_v,
    3)``), block by block of u-points (:func:`grid_block_positions`); block ``k`` is
    u-points ``starts[k]:starts[k+1]``, its net rows ``rows[row_starts[k]:row_starts[k+1]]``,
    ``first[a]`` the place of u-point ``a``'s first row among them; ``scratch[0]`` holds a
    block's row table (reused: a fresh table per block would be paged in again and again).
    ``vruns`` is ``(bplan, planes, run_starts, run_kinds)`` for the vector loops of
    :func:`surfmod.eval.row_stage.contract_rows`, or ``None`` for the one-point-at-a-time
    stage :func:`grid_rows`.

    Only the stages a call can reach are compiled: numba prunes the ``vruns is None``
    branches by the argument's type, so a grid on a small net (no vector runs) compiles
    neither the vector row stage nor the sliding ring (a quarter of the compile time of
    all of them: 40 s against 178 s into an empty cache on the loaded 2-core machine).
    For the same reason positions and partials are two entries."""
    for blk in range(starts.size - 1):
        grid_block_positions(bv, sv, q, ctrl, dim, bu, p, rational, b0, out, scratch[0], starts, rows, row_starts,
                             first, blk, vruns)


@njit(cache=True, error_model="numpy")
def partials_grid(bv, sv, q, ctrl, dim, bu, p, rational, binom, b0, out, scratch, starts, rows, row_starts, first,
                  vruns):
    """The grid of partials ``(n_u, N_v, K, K, 3)``, ``K = bu.shape[1]``, as
    :func:`positions_grid` (:func:`grid_block_derivatives` per block)."""
    for blk in range(starts.size - 1):
        grid_block_derivatives(bv, sv, q, ctrl, dim, bu, p, rational, binom, b0, out, scratch[0], starts, rows,
                               row_starts, first, blk, vruns)


@njit(cache=True, error_model="numpy")
def _block_table(bv, sv, q, ctrl, dim, space, starts, rows, row_starts, blk, vruns):
    """A block's net rows contracted with the v-basis (:func:`grid_rows`, or the vector
    loops of :func:`surfmod.eval.row_stage.contract_rows` when ``vruns`` is given) into a
    table in ``space`` (its thread's scratch), and its u-range.  Blocks share nothing but
    the read-only inputs, so the parallel variant (:mod:`surfmod.eval.parallel`) runs them
    on several threads."""
    mine = rows[row_starts[blk] : row_starts[blk + 1]]
    kk, nv = bv.shape[1], sv.size
    table = space[: mine.size * kk * dim * nv].reshape((mine.size, kk, dim, nv))
    if vruns is None:
        grid_rows(bv, sv, q, ctrl, mine, dim, table)
    else:
        bplan, planes, run_starts, run_kinds = vruns
        contract_rows(bv, bplan, sv, q, ctrl, planes, mine, dim, table, run_starts, run_kinds)
    return table, starts[blk], starts[blk + 1]


@njit(cache=True, error_model="numpy")
def grid_block_positions(bv, sv, q, ctrl, dim, bu, p, rational, b0, out, space, starts, rows, row_starts, first,
                         blk, vruns):
    """One block of :func:`positions_grid` (on a big net with the stages interleaved,
    :mod:`surfmod.eval.sliding`, when it suits)."""
    a0, a1 = starts[blk], starts[blk + 1]
    if vruns is not None:
        if sliding.suits(p, first, a0, a1, space, dim, sv.size, vruns[3]):
            sliding.block_positions(bv, sv, q, ctrl, dim, bu, p, rational, b0, out, space,
                                    rows[row_starts[blk] : row_starts[blk + 1]], a0, a1, first, vruns)
            return
    table, a0, a1 = _block_table(bv, sv, q, ctrl, dim, space, starts, rows, row_starts, blk, vruns)
    grid_positions(bu[a0:a1], first[a0:a1], p, table, rational, b0, out[a0:a1])


@njit(cache=True, error_model="numpy")
def grid_block_derivatives(bv, sv, q, ctrl, dim, bu, p, rational, binom, b0, out, space, starts, rows, row_starts,
                           first, blk, vruns):
    """One block of :func:`partials_grid`: to order 2 by
    :func:`surfmod.eval.partials_stage.order2_block`, other orders by :func:`grid_derivatives`."""
    table, a0, a1 = _block_table(bv, sv, q, ctrl, dim, space, starts, rows, row_starts, blk, vruns)
    if bu.shape[1] == 3:
        order2_block(bu[a0:a1], first[a0:a1], p, table, rational, b0, out[a0:a1])
    else:
        grid_derivatives(bu[a0:a1], first[a0:a1], p, table, rational, binom, b0, out[a0:a1])


@njit(cache=True, error_model="numpy")
def grid_rows(bv, sv, q, ctrl, rows, dim, out):
    """First stage of the grid: ``out[r, l, d, b] = sum_j bv[b, l, j] ctrl[rows[r], sv[b]-q+j, d]``
    for ``d < dim``: the net rows ``rows`` (only those the u-points need) contracted
    with the v-basis, two rows per pass (a v-point's basis values and window are loaded
    once for both; each row's sums are those of the one-row pass,
    :func:`surfmod.eval.row_stage.row_points`, so the same values)."""
    kk = bv.shape[1]
    nv = sv.size
    basis = bv.reshape(-1)
    per_point = uint64(kk * (q + 1))
    pairs = rows.size // 2
    for r2 in range(pairs):  # two rows per pass: the basis values are loaded once for both
        ra, rb = 2 * r2, 2 * r2 + 1
        row_a, row_b = ctrl[rows[ra]].reshape(-1), ctrl[rows[rb]].reshape(-1)
        dst_a, dst_b = out[ra].reshape(-1), out[rb].reshape(-1)
        for b in range(nv):
            ub = uint64(b)
            s = uint64(4 * (sv[b] - q))
            for l in range(kk):
                o = ub * per_point + uint64(l * (q + 1))
                c = basis[o]  # first term first: the sums of row_stage.row_points
                x, y, z, w = c * row_a[s], c * row_a[s + U1], c * row_a[s + U2], c * row_a[s + U3]
                x2, y2, z2, w2 = c * row_b[s], c * row_b[s + U1], c * row_b[s + U2], c * row_b[s + U3]
                for j in range(1, q + 1):
                    c = basis[o + uint64(j)]
                    t = s + uint64(4 * j)
                    x += c * row_a[t]
                    y += c * row_a[t + U1]
                    z += c * row_a[t + U2]
                    w += c * row_a[t + U3]
                    x2 += c * row_b[t]
                    y2 += c * row_b[t + U1]
                    z2 += c * row_b[t + U2]
                    w2 += c * row_b[t + U3]
                t = uint64(l * dim * nv) + ub
                dst_a[t] = x
                dst_a[t + uint64(nv)] = y
                dst_a[t + uint64(2 * nv)] = z
                dst_b[t] = x2
                dst_b[t + uint64(nv)] = y2
                dst_b[t + uint64(2 * nv)] = z2
                if dim == 4:
                    dst_a[t + uint64(3 * nv)] = w
                    dst_b[t + uint64(3 * nv)] = w2
    for r in range(2 * pairs, rows.size):
        row_points(bv, sv, q, ctrl[rows[r]].reshape(-1), dim, out[r].reshape(-1), 0, nv, 0, nv)


@njit(cache=True, inline="always", error_model="numpy")
def _combine_rows(bu, a, first, p, w, kk, dim, acc):
    """``acc[k, l, d, :n_v] = sum_i bu[a, k, i] w[first[a]+i, l, d, :]`` (v on the
    vector axis); up to degree 3 as one four-term pass per plane."""
    r0 = first[a]
    nv = w.shape[3]
    if p <= 3:
        r1, r2, r3 = r0 + min(1, p), r0 + min(2, p), r0 + min(3, p)
        for k in range(kk):
            c0 = bu[a, k, 0]
            c1 = bu[a, k, 1] if p >= 1 else 0.0
            c2 = bu[a, k, 2] if p >= 2 else 0.0
            c3 = bu[a, k, 3] if p >= 3 else 0.0
            for l in range(kk):
                for d in range(dim):
                    w0, w1, w2, w3 = w[r0, l, d], w[r1, l, d], w[r2, l, d], w[r3, l, d]
                    dst = acc[k, l, d]
                    for b in range(nv):
                        dst[b] = c0 * w0[b] + c1 * w1[b] + c2 * w2[b] + c3 * w3[b]
        return
    for k in range(kk):
        for l in range(kk):
            for d in range(dim):
                c = bu[a, k, 0]
                for b in range(nv):
                    acc[k, l, d, b] = c * w[r0, l, d, b]
                for i in range(1, p + 1):
                    c = bu[a, k, i]
                    for b in range(nv):
                        acc[k, l, d, b] += c * w[r0 + i, l, d, b]


@njit(cache=True, error_model="numpy")
def grid_positions(bu, first, p, w, rational, b0, out):
    """Second stage for positions: ``out[:, b0:b0+n_v]`` of ``out (n_u, N_v, 3)``
    point-major, the division by the weight fused into the (interleaving) store."""
    nv = w.shape[3]
    dim = 4 if rational else 3
    if p <= 3:
        positions_low_degree(bu, first, p, w, rational, b0, out)
        return
    acc = np.empty((1, 1, 4, nv))
    for a in range(bu.shape[0]):
        _combine_rows(bu, a, first, p, w, 1, dim, acc)
        row = out[a].reshape(-1)  # flat, unsigned offsets (see U1)
        o = uint64(3 * b0)
        for b in range(nv):
            t = o + U3 * uint64(b)
            inv_w = 1.0 / acc[0, 0, 3, b] if rational else 1.0
            row[t] = acc[0, 0, 0, b] * inv_w
            row[t + U1] = acc[0, 0, 1, b] * inv_w
            row[t + U2] = acc[0, 0, 2, b] * inv_w


@njit(cache=True, error_model="numpy")
def grid_derivatives(bu, first, p, w, rational, binom, b0, out):
    """Second stage for partials of any order (order 2 has its own,
    :mod:`surfmod.eval.partials_stage`): for each u-point combine its p+1 rows of ``w`` on
    the cache-resident planes of a scratch ``acc`` (every partial and coordinate a
    contiguous row of v), apply the quotient rule there (rational), then store each
    point's ``3 K^2`` values together into ``out[:, b0:b0+n_v]`` of the point-major ``out
    (n_u, N_v, K, K, 3)``, so the output is written once, front to back."""
    kk = bu.shape[1]
    nv = w.shape[3]
    dim = 4 if rational else 3
    acc = np.empty((kk, kk, 4, nv))
    for a in range(bu.shape[0]):
        _combine_rows(bu, a, first, p, w, kk, dim, acc)
        if rational:
            quotient_planes(acc, binom)
        points = out[a]
        for b in range(nv):
            point = points[b0 + b]
            for k in range(kk):
                for l in range(kk):
                    point[k, l, 0] = acc[k, l, 0, b]
                    point[k, l, 1] = acc[k, l, 1, b]
                    point[k, l, 2] = acc[k, l, 2, b]
