"""The compiled (numba) twin of :mod:`surfmod.eval.tensor_grid`: the grid ``us x vs``,
positions and partials to any order, one path: a ring of contracted net rows
(:mod:`surfmod.eval.row_stage`) combined per sorted u-point (:func:`_combine`, or
:func:`surfmod.eval.position_stage.positions_pass` for positions).  Conventions as in
:mod:`surfmod.eval.kernels`.  See :doc:`/design_eval` (section "The compiled grid").
"""

from __future__ import annotations

import numpy as np
from numba import njit, uint64

from .kernels import quotient_planes
from .position_stage import pass_extent, positions_pass
from .row_stage import contract_row, contract_row_pair

#: v-points of the planes a u-point's partials are formed on: 36 planes (order 2) of
#: 64 doubles stay in L1
PLANE_POINTS = 64


@njit(cache=True, error_model="numpy")
def tensor_grid_compiled(bv, bplan, sv, q, ctrl, planes, dim, bu, p, rational, binom, out, origin, space, ring_rows,
                         chunk, first, run_starts, run_kinds):
    """The grid ``us x vs`` into ``out`` (point-major ``(n_u, N_v, K, K, 3)``,
    ``K = bu.shape[1]``; positions are ``K = 1``): :func:`tensor_grid_block` on all u-points."""
    tensor_grid_block(bv, bplan, sv, q, ctrl, planes, dim, bu, p, rational, binom, out, origin, space, ring_rows, chunk,
                      first, run_starts, run_kinds, 0, bu.shape[0])


@njit(cache=True, error_model="numpy")
def tensor_grid_block(bv, bplan, sv, q, ctrl, planes, dim, bu, p, rational, binom, out, origin, space, ring_rows, chunk,
                      first, run_starts, run_kinds, a0, a1):
    """u-points ``a0:a1`` of the grid, in ascending order: ``first[a]`` is u-point ``a``'s
    lowest net row (its span minus ``p``), ``bu (n_u, K, p+1)`` its basis and derivatives;
    ``bv (n_v, K, q+1)`` and ``sv`` the v-basis and spans, ``bplan``/``planes``/``run_*``
    the vector loops of the row stage (:mod:`surfmod.eval.row_stage`; an empty ``planes``
    when there are no runs of consecutive spans).  ``space`` holds the ring: ``ring_rows``
    rows of ``(K, dim, chunk)``.  ``origin`` (3 values) is added to the positions: the
    net is taken about it (:func:`surfmod.eval.local.prepare`); it is added to each
    u-point's chunk just after it is written, while that is still in cache."""
    kk, nv = bu.shape[1], sv.size
    ring = space[: ring_rows * kk * dim * chunk].reshape((ring_rows, kk, dim, chunk))
    flat = ring.reshape(-1)
    fast = kk == 1 and p <= 3
    moved = origin[0] != 0.0 or origin[1] != 0.0 or origin[2] != 0.0
    width = min(chunk, PLANE_POINTS)
    acc = np.ones((kk, kk, 4, width))  # ones: the weights of lanes a short last piece leaves
    gather = np.empty(3 * kk * kk, dtype=np.uint64)  # where each value of a point is in `acc`
    for f in range(gather.size):
        gather[f] = (f // 3 * 4 + f % 3) * width
    for c0 in range(0, nv, chunk):  # loop over cache chunks of v-points, not points
        c1 = min(nv, c0 + chunk)
        ready = first[a0]  # the next row to contract; rows below it are not read again
        a = a0
        while a < a1:
            if fast:
                _, top = pass_extent(first, p, a, a1)
            else:
                top = first[a] + p
            ready = max(ready, first[a])  # rows between two u-points' rows: not needed
            while ready < top:  # two rows a pass: their basis values loaded once
                contract_row_pair(bv, bplan, sv, q, ctrl, planes, ready, ready + 1, dim, flat,
                                  (ready % ring_rows) * kk * dim * chunk - c0,
                                  ((ready + 1) % ring_rows) * kk * dim * chunk - c0, chunk, run_starts, run_kinds,
                                  c0, c1)
                ready += 2
            if ready == top:
                contract_row(bv, bplan, sv, q, ctrl[ready], planes[ready], dim, flat,
                             (ready % ring_rows) * kk * dim * chunk - c0, chunk, run_starts, run_kinds, c0, c1)
                ready += 1
            if fast:
                done = positions_pass(bu, first, p, ring, rational, c0, out, a, a1, ring_rows, c1 - c0)
                if moved:
                    for b in range(a, a + done):
                        _add_origin(out[b], c0, c1, origin)
                a += done
                continue
            for s0 in range(0, c1 - c0, width):  # planes of `width` points: they stay in L1
                n = min(width, c1 - c0 - s0)
                _combine(bu, a, first[a], p, ring, ring_rows, dim, acc, s0, n)
                if rational:
                    quotient_planes(acc, binom)
                _store(acc, out[a], c0 + s0, n, gather)
            if moved:
                _add_origin(out[a], c0, c1, origin)
            a += 1


@njit(cache=True, inline="always", error_model="numpy")
def _add_origin(points, c0, c1, origin):
    """``origin`` added to the positions of ``points[c0:c1]`` (``(N_v, K, K, 3)``)."""
    flat, size = points.reshape(-1), points[0].size
    for b in range(c0, c1):
        t = b * size
        flat[t] += origin[0]
        flat[t + 1] += origin[1]
        flat[t + 2] += origin[2]


@njit(cache=True, inline="always", error_model="numpy")
def _combine(bu, a, r0, p, ring, ring_rows, dim, acc, s0, n):
    """``acc[k, l, d, :n] = sum_i bu[a, k, i] ring[(r0 + i) % ring_rows, l, d, s0:s0+n]``;
    up to degree 3 as one four-term sum a plane (rows past the degree repeat the last
    one with coefficient 0), above it term by term.  Both arrays are read through flat
    views by unsigned offsets: a view per plane would cost its reference counting, and
    unsigned offsets spare the wraparound checks that keep loops from vectorizing."""
    kk, width = bu.shape[1], acc.shape[3]
    src, dst = ring.reshape(-1), acc.reshape(-1)
    row, plane = kk * dim * ring.shape[3], ring.shape[3]
    if p <= 3:
        o0, o1 = (r0 % ring_rows) * row + s0, ((r0 + min(1, p)) % ring_rows) * row + s0
        o2, o3 = ((r0 + min(2, p)) % ring_rows) * row + s0, ((r0 + min(3, p)) % ring_rows) * row + s0
        if kk == 3:  # partials to order 2: each row window loaded once for the three k
            c00, c01, c02, c03 = _four(bu, a, 0, p)
            c10, c11, c12, c13 = _four(bu, a, 1, p)
            c20, c21, c22, c23 = _four(bu, a, 2, p)
            for l in range(3):
                for d in range(dim):
                    f = (l * dim + d) * plane
                    x0, x1, x2, x3 = uint64(o0 + f), uint64(o1 + f), uint64(o2 + f), uint64(o3 + f)
                    t0 = uint64((l * 4 + d) * width)
                    t1, t2 = t0 + uint64(12 * width), t0 + uint64(24 * width)
                    for b in range(n):
                        ub = uint64(b)
                        v0, v1, v2, v3 = src[x0 + ub], src[x1 + ub], src[x2 + ub], src[x3 + ub]
                        dst[t0 + ub] = c00 * v0 + c01 * v1 + c02 * v2 + c03 * v3
                        dst[t1 + ub] = c10 * v0 + c11 * v1 + c12 * v2 + c13 * v3
                        dst[t2 + ub] = c20 * v0 + c21 * v1 + c22 * v2 + c23 * v3
            return
        for k in range(kk):
            c0, c1, c2, c3 = _four(bu, a, k, p)
            for l in range(kk):
                for d in range(dim):
                    f = (l * dim + d) * plane
                    x0, x1, x2, x3 = uint64(o0 + f), uint64(o1 + f), uint64(o2 + f), uint64(o3 + f)
                    t = uint64(((k * kk + l) * 4 + d) * width)
                    for b in range(n):
                        ub = uint64(b)
                        dst[t + ub] = c0 * src[x0 + ub] + c1 * src[x1 + ub] + c2 * src[x2 + ub] + c3 * src[x3 + ub]
        return
    for k in range(kk):
        for l in range(kk):
            for d in range(dim):
                f = (l * dim + d) * plane + s0
                t = uint64(((k * kk + l) * 4 + d) * width)
                c, x = bu[a, k, 0], uint64((r0 % ring_rows) * row + f)
                for b in range(n):
                    dst[t + uint64(b)] = c * src[x + uint64(b)]
                for i in range(1, p + 1):
                    c, x = bu[a, k, i], uint64(((r0 + i) % ring_rows) * row + f)
                    for b in range(n):
                        dst[t + uint64(b)] += c * src[x + uint64(b)]


@njit(cache=True, inline="always", error_model="numpy")
def _four(bu, a, k, p):
    """The u-basis row ``bu[a, k]`` padded with zeros to four coefficients."""
    return (bu[a, k, 0], bu[a, k, 1] if p >= 1 else 0.0, bu[a, k, 2] if p >= 2 else 0.0,
            bu[a, k, 3] if p >= 3 else 0.0)


@njit(cache=True, inline="always", error_model="numpy")
def _store(acc, points, o, n, gather):
    """Points ``:n`` of the planes ``acc`` into ``points[o:o+n]`` (``(N_v, K, K, 3)``),
    each point's ``3 K^2`` values together, so the output is written once, front to back:
    value ``f`` of point ``b`` is ``acc`` at flat offset ``gather[f] + b``."""
    src, dst = acc.reshape(-1), points.reshape(-1)
    size = uint64(gather.size)
    for b in range(n):
        t, ub = uint64(o + b) * size, uint64(b)
        for f in range(gather.size):
            dst[t + uint64(f)] = src[gather[f] + ub]
