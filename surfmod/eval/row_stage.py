"""The row stage of the grid (:mod:`surfmod.eval.tensor_grid_compiled`): a net row the
u-points need, contracted with the v-basis (:func:`contract_row`,
:func:`contract_row_pair`), in vector loops over the runs of v-points in consecutive spans
(:func:`runs`, on the planes of :func:`net_planes`).  Each lane's sum keeps the scalar
loop's order, so the values do not depend on the runs.
See :doc:`/design_eval` (section "The compiled grid").

>>> import numpy as np
>>> runs(np.array([3, 3, 3, 4, 5, 6, 7, 8, 10]), min_run=4)
(array([0, 2, 8, 9]), array([2, 1, 2]))
"""

from __future__ import annotations

import numpy as np
from numba import njit, uint64

from .kernels import U1, U2, U3

#: run kinds: points in consecutive spans (a vector loop), others (one point at a time)
NEXT_SPAN, SCALAR = 1, 2
#: shortest run of consecutive spans worth a vector loop (shorter ones join the scalar runs)
MIN_RUN = 32


@njit(cache=True, error_model="numpy")
def runs(sv, min_run=MIN_RUN):
    """Split the v-points by their spans ``sv`` into runs: ``(starts, kinds)``, run ``k``
    is points ``starts[k]:starts[k+1]``, of kind :data:`NEXT_SPAN` (``sv[b] = sv[start] +
    b - start``, at least ``min_run`` points) or :data:`SCALAR` (the others)."""
    n = sv.size
    starts = np.empty(n + 1, dtype=np.int64)
    kinds = np.empty(n, dtype=np.int64)
    count = 0
    b = 0
    while b < n:
        e = b + 1  # the longest stretch from b of spans one apart
        while e < n and sv[e] - sv[e - 1] == 1:
            e += 1
        if e - b >= min_run:
            kind = NEXT_SPAN
        else:
            kind, e = SCALAR, b + 1
        if count > 0 and kind == SCALAR and kinds[count - 1] == SCALAR:
            starts[count] = e  # extend the scalar run before
        else:
            kinds[count] = kind
            starts[count] = b
            starts[count + 1] = e
            count += 1
        b = e
    starts[count] = n
    return starts[: count + 1].copy(), kinds[:count].copy()


def net_planes(ctrl: np.ndarray) -> np.ndarray:
    """The homogeneous net ``(n, m, 4)`` as coordinate planes ``(n, 4, m)``: each net row's
    x, y, z and w contiguous, as the vector loops of :func:`contract_row` read them.

    >>> import numpy as np
    >>> net_planes(np.arange(8.0).reshape(1, 2, 4))[0]
    array([[0., 4.],
           [1., 5.],
           [2., 6.],
           [3., 7.]])
    """
    return np.ascontiguousarray(ctrl.transpose(0, 2, 1))


@njit(cache=True, inline="always", error_model="numpy")
def contract_row(bv, bplan, sv, q, net_row, row_planes, dim, dst, o_dst, stride, starts, kinds, v0, v1):
    """One net row (``net_row`` ``(m, 4)``, ``row_planes`` ``(4, m)``) contracted for the
    v-points ``v0:v1``: ``dst[o_dst + (l dim + d) stride + b]`` for ``b`` in ``v0:v1``.
    The vector loops index three flat arrays by offsets: an array view per run would cost
    its reference counting, and a loop storing to one array needs few runtime alias
    checks before LLVM vectorizes it."""
    kk, nv, m = bplan.shape[0], sv.size, row_planes.shape[1]
    basis = bplan.reshape(-1)
    per_l = (q + 1) * nv
    src = row_planes.reshape(-1)
    for k in range(kinds.size):
        b0, b1 = starts[k], starts[k + 1]
        lo, hi = max(b0, v0), min(b1, v1)
        if lo >= hi:
            continue
        if kinds[k] == SCALAR:
            row_points(bv, sv, q, net_row.reshape(-1), dim, dst, o_dst, stride, lo, hi)
            continue
        for l in range(kk):
            for d in range(dim):
                _next_span(basis, l * per_l, nv, src, d * m + sv[b0] - q - b0, q, dst, o_dst + (l * dim + d) * stride,
                           lo, hi)


@njit(cache=True, inline="always", error_model="numpy")
def contract_row_pair(bv, bplan, sv, q, ctrl, planes, ra, rb, dim, dst, o_a, o_b, stride, starts, kinds, v0, v1):
    """:func:`contract_row` for net rows ``ra`` and ``rb`` at once (into ``dst`` from
    ``o_a`` and ``o_b``): the cubic vector loop loads each basis value once for both
    rows; every sum is the one-row sum, term for term."""
    if q != 3:
        contract_row(bv, bplan, sv, q, ctrl[ra], planes[ra], dim, dst, o_a, stride, starts, kinds, v0, v1)
        contract_row(bv, bplan, sv, q, ctrl[rb], planes[rb], dim, dst, o_b, stride, starts, kinds, v0, v1)
        return
    kk, nv, m = bplan.shape[0], sv.size, planes.shape[2]
    basis = bplan.reshape(-1)
    per_l = 4 * nv
    src = planes.reshape(-1)  # both rows through one array: few runtime alias checks
    for k in range(kinds.size):
        b0, b1 = starts[k], starts[k + 1]
        lo, hi = max(b0, v0), min(b1, v1)
        if lo >= hi:
            continue
        if kinds[k] == SCALAR:
            row_points(bv, sv, q, ctrl[ra].reshape(-1), dim, dst, o_a, stride, lo, hi)
            row_points(bv, sv, q, ctrl[rb].reshape(-1), dim, dst, o_b, stride, lo, hi)
            continue
        shift = sv[b0] - q - b0
        for l in range(kk):
            for d in range(dim):
                sa, sb = ra * 4 * m + d * m + shift, rb * 4 * m + d * m + shift
                da, db = o_a + (l * dim + d) * stride, o_b + (l * dim + d) * stride
                o_basis = l * per_l
                for b in range(lo, hi):
                    c = uint64(o_basis + b)
                    c0, c1, c2, c3 = basis[c], basis[c + uint64(nv)], basis[c + uint64(2 * nv)], basis[c + uint64(3 * nv)]
                    t = uint64(sa + b)
                    dst[uint64(da + b)] = c0 * src[t] + c1 * src[t + U1] + c2 * src[t + U2] + c3 * src[t + U3]
                    t = uint64(sb + b)
                    dst[uint64(db + b)] = c0 * src[t] + c1 * src[t + U1] + c2 * src[t + U2] + c3 * src[t + U3]


@njit(cache=True, inline="always", error_model="numpy")
def row_points(bv, sv, q, net_row, dim, dst, o_dst, stride, b0, b1):
    """v-points ``b0:b1`` of one net row (``net_row``: ``(m, 4)`` flat) one at a time, the
    four coordinates of a pole together: ``dst[o_dst + (l dim + d) stride + b] = sum_j
    bv[b, l, j] net_row[4 (sv[b] - q + j) + d]`` (unsigned offsets: no wraparound
    checks)."""
    kk = bv.shape[1]
    basis = bv.reshape(-1)
    per_point = uint64(kk * (q + 1))
    step = uint64(stride)
    for b in range(b0, b1):
        ub = uint64(b)
        s = uint64(4 * (sv[b] - q))
        for l in range(kk):
            o = ub * per_point + uint64(l * (q + 1))
            c = basis[o]
            x, y, z, w = c * net_row[s], c * net_row[s + U1], c * net_row[s + U2], c * net_row[s + U3]
            for j in range(1, q + 1):
                c = basis[o + uint64(j)]
                t = s + uint64(4 * j)
                x += c * net_row[t]
                y += c * net_row[t + U1]
                z += c * net_row[t + U2]
                w += c * net_row[t + U3]
            t = uint64(o_dst + l * dim * stride + b)
            dst[t] = x
            dst[t + step] = y
            dst[t + U2 * step] = z
            if dim == 4:
                dst[t + U3 * step] = w


@njit(cache=True, inline="always", error_model="numpy")
def _next_span(basis, o_basis, nv, src, o_src, q, dst, o_dst, b0, b1):
    """Points ``b0:b1`` in consecutive spans: ``dst[o_dst + b] = sum_j basis[o_basis + j
    nv + b] src[o_src + b + j]``, contiguous streams."""
    if q == 3:
        for b in range(b0, b1):
            c = uint64(o_basis + b)
            s = uint64(o_src + b)
            dst[uint64(o_dst + b)] = (basis[c] * src[s] + basis[c + uint64(nv)] * src[s + U1]
                                      + basis[c + uint64(2 * nv)] * src[s + U2] + basis[c + uint64(3 * nv)] * src[s + U3])
        return
    for b in range(b0, b1):
        dst[uint64(o_dst + b)] = basis[uint64(o_basis + b)] * src[uint64(o_src + b)]
    for j in range(1, q + 1):  # term by term: the order of the scalar sum
        for b in range(b0, b1):
            dst[uint64(o_dst + b)] += basis[uint64(o_basis + j * nv + b)] * src[uint64(o_src + b + j)]
