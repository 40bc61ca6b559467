"""Compiled (numba) twins of :mod:`surfmod.eval.scattered`: positions and partials at
scattered parameter pairs, one loop over the points (bucketed span search, basis
derivatives, local contraction, the quotient rule).  ``scattered_compiled`` computes what
:func:`surfmod.eval.scattered.scattered` does (to a few ulps: the kernels multiply by
reciprocal knot differences where A2.3 divides); ``scattered_positions_compiled`` is its
order-0 case with the sums kept in registers.  The work is cut into chunks of
:data:`~surfmod.eval.kernels.SCATTER_CHUNK` points, which the ``_parallel`` variants
(:mod:`surfmod.eval.parallel`) share among threads.  Conventions as in
:mod:`surfmod.eval.kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .kernels import SCATTER_CHUNK, basis_ders_point, find_span_bucketed, position_at, quotient_planes

#: points per block of the scattered-derivative kernel (its planes stay in L1/L2)
POINT_BLOCK = 128


@njit(cache=True, error_model="numpy")
def scattered_compiled(ku, p, kv, q, ctrl, u, v, order, rational, binom, inv_u, inv_v, bucket_u, bucket_v, out,
                       origin=None):
    """Mixed partials at scattered pairs into ``out (N, K, K, 3)`` (Cartesian).

    ``ctrl`` is ``(n, m, 4)``: homogeneous for a rational net, the weight column unused
    otherwise.  Points go in blocks: per point the spans, the basis derivatives and a
    gather of the local ``(p+1) x (q+1)`` net into planes; then the contraction and the
    quotient rule run over the block with the points on the contiguous (vector) axis.
    ``origin`` (3 values, or None) is added to the positions as they are stored: the
    point a far net is taken about (:func:`surfmod.eval.local.prepare`)."""
    for c in range((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        scattered_chunk(ku, p, kv, q, ctrl, u, v, order, rational, binom, inv_u, inv_v,
                        bucket_u, bucket_v, out, c, origin)


@njit(cache=True, error_model="numpy")
def scattered_chunk(ku, p, kv, q, ctrl, u, v, order, rational, binom, inv_u, inv_v, bucket_u,
                    bucket_v, out, chunk, origin=None):
    """Points ``chunk * SCATTER_CHUNK`` onwards (one chunk) of :func:`scattered_compiled`,
    with their own scratch planes: chunks are independent."""
    n, m = ctrl.shape[0], ctrl.shape[1]
    kk = order + 1
    nb = POINT_BLOCK
    dim = 4 if rational else 3
    ndu_u, ndu_v = np.empty((p + 1, p + 1)), np.empty((q + 1, q + 1))
    lu, ru, tu = np.empty(p + 1), np.empty(p + 1), np.empty(p + 1)
    lv, rv, tv = np.empty(q + 1), np.empty(q + 1), np.empty(q + 1)
    du, dv = np.empty((kk, p + 1)), np.empty((kk, q + 1))
    bu, bv = np.empty((kk, p + 1, nb)), np.empty((kk, q + 1, nb))
    local = np.empty((p + 1, q + 1, 4, nb))
    row = np.empty((kk, 4, nb))
    h = np.ones((kk, kk, 4, nb))  # lanes past a short last block keep finite values
    t0u, scale_u, table_u = bucket_u
    t0v, scale_v, table_v = bucket_v
    end = min(u.size, (chunk + 1) * SCATTER_CHUNK)
    for a0 in range(chunk * SCATTER_CHUNK, end, nb):
        cnt = min(nb, end - a0)
        for b in range(cnt):
            su = find_span_bucketed(ku, p, n, u[a0 + b], t0u, scale_u, table_u)
            sv = find_span_bucketed(kv, q, m, v[a0 + b], t0v, scale_v, table_v)
            basis_ders_point(ku, p, su, u[a0 + b], order, inv_u, ndu_u, lu, ru, tu, du)
            basis_ders_point(kv, q, sv, v[a0 + b], order, inv_v, ndu_v, lv, rv, tv, dv)
            for k in range(kk):
                for i in range(p + 1):
                    bu[k, i, b] = du[k, i]
                for j in range(q + 1):
                    bv[k, j, b] = dv[k, j]
            for i in range(p + 1):
                for j in range(q + 1):
                    for d in range(4):
                        local[i, j, d, b] = ctrl[su - p + i, sv - q + j, d]
        for i in range(p + 1):
            for l in range(kk):
                for d in range(dim):
                    for b in range(cnt):
                        row[l, d, b] = bv[l, 0, b] * local[i, 0, d, b]
                    for j in range(1, q + 1):
                        for b in range(cnt):
                            row[l, d, b] += bv[l, j, b] * local[i, j, d, b]
            for k in range(kk):
                for l in range(kk):
                    for d in range(dim):
                        if i == 0:
                            for b in range(cnt):
                                h[k, l, d, b] = bu[k, 0, b] * row[l, d, b]
                        else:
                            for b in range(cnt):
                                h[k, l, d, b] += bu[k, i, b] * row[l, d, b]
        if rational:  # on the whole block: contiguous planes vectorize
            quotient_planes(h, binom)
        for b in range(cnt):
            for k in range(kk):
                for l in range(kk):
                    for d in range(3):
                        out[a0 + b, k, l, d] = h[k, l, d, b]
            if origin is not None:
                for d in range(3):
                    out[a0 + b, 0, 0, d] += origin[d]


@njit(cache=True, error_model="numpy")
def scattered_positions_compiled(ku, p, kv, q, ctrl, u, v, rational, inv_u, inv_v, bucket_u, bucket_v, out,
                                 origin=None):
    """Positions at scattered pairs into ``out (N, 3)``: the order-0 case of
    :func:`scattered_compiled` with the cheaper Cox-de Boor triangle (A2.2) and the
    sums kept in registers (``origin`` added, if given)."""
    for c in range((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        scattered_positions_chunk(ku, p, kv, q, ctrl, u, v, rational, inv_u, inv_v, bucket_u, bucket_v, out, c,
                                  origin)


@njit(cache=True, error_model="numpy")
def scattered_positions_chunk(ku, p, kv, q, ctrl, u, v, rational, inv_u, inv_v, bucket_u, bucket_v, out, chunk,
                              origin=None):
    """One chunk of :func:`scattered_positions_compiled` (points ``chunk * SCATTER_CHUNK`` on)."""
    nu_, nv_ = np.empty(p + 1), np.empty(q + 1)
    lu, ru = np.empty(p + 1), np.empty(p + 1)
    lv, rv = np.empty(q + 1), np.empty(q + 1)
    for a in range(chunk * SCATTER_CHUNK, min(u.size, (chunk + 1) * SCATTER_CHUNK)):
        x, y, z = position_at(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, u[a], v[a],
                              lu, ru, nu_, lv, rv, nv_)
        if origin is not None:
            x, y, z = x + origin[0], y + origin[1], z + origin[2]
        out[a, 0] = x
        out[a, 1] = y
        out[a, 2] = z

