"""Tensor-product evaluation: contract basis arrays with (homogeneous) control points.

Control points arrive in homogeneous form: ``(..., 3)`` for polynomial splines or
``(..., 4)`` = ``(w x, w y, w z, w)`` for rational ones.  The result keeps that last axis;
:mod:`surfmod.eval.rational` turns it into Cartesian derivatives.
"""

from __future__ import annotations

import numpy as np

from .basis import basis_derivatives, basis_matrix, find_spans


# Scattered points are processed in blocks: the per-block temporaries stay in cache, and
# memory stays bounded for any number of points.
BLOCK = 1 << 14


def _planar(ctrl: np.ndarray) -> np.ndarray:
    """Control points as coordinate planes ``(dim, n_points)`` for fast ``take``."""
    return np.ascontiguousarray(ctrl.reshape(-1, ctrl.shape[-1]).T)


def curve_derivatives(knots, degree, ctrl, t, order):
    """Derivatives 0..order of a spline curve: ``(len(t), order + 1, dim)``."""
    t = np.asarray(t, dtype=float).ravel()
    planes = _planar(ctrl)
    out = np.empty((order + 1, planes.shape[0], t.size))  # (K, dim, N), planar
    for b0 in range(0, t.size, BLOCK):
        tb = t[b0 : b0 + BLOCK]
        spans = find_spans(knots, degree, ctrl.shape[0], tb)
        ders = basis_derivatives(knots, degree, spans, tb, order).transpose(1, 2, 0)  # (K, p+1, N)
        acc = np.zeros((order + 1, planes.shape[0], tb.size))
        for r in range(degree + 1):
            acc += ders[:, r, None, :] * planes.take(spans - degree + r, axis=1)[None]
        out[..., b0 : b0 + BLOCK] = acc
    return out.transpose(2, 0, 1)


def surface_derivatives(knots_u, p, knots_v, q, ctrl, u, v, order):
    """Mixed partials up to ``order`` at scattered pairs: ``(N, order+1, order+1, dim)``.

    Entry ``[a, k, l]`` is d^(k+l) S / du^k dv^l at ``(u[a], v[a])``.  Per block: for each
    of the p+1 rows of the local net, gather its q+1 points and contract them with the
    v-basis, then contract the rows with the u-basis, all with the points on the last
    (contiguous) axis.  The result is a view of planar memory.
    """
    u = np.asarray(u, dtype=float).ravel()
    v = np.asarray(v, dtype=float).ravel()
    n, m, dim = ctrl.shape
    k_ = order + 1
    planes = _planar(ctrl)
    out = np.empty((k_, k_, dim, u.size))
    row_offsets = np.arange(q + 1)[:, None]
    for b0 in range(0, u.size, BLOCK):
        ub, vb = u[b0 : b0 + BLOCK], v[b0 : b0 + BLOCK]
        su = find_spans(knots_u, p, n, ub)
        sv = find_spans(knots_v, q, m, vb)
        bu = basis_derivatives(knots_u, p, su, ub, order).transpose(1, 2, 0)  # (K, p+1, N)
        bv = basis_derivatives(knots_v, q, sv, vb, order).transpose(1, 2, 0)  # (K, q+1, N)
        first = (su - p) * m + (sv - q)
        acc = np.zeros((k_, k_, dim, ub.size))
        for i in range(p + 1):
            local = planes.take(first + i * m + row_offsets, axis=1)  # (dim, q+1, N)
            row = bv[:, 0, None, :] * local[None, :, 0, :]  # row[l] = sum_j dNv_l,j P[i, j]
            for j in range(1, q + 1):
                row += bv[:, j, None, :] * local[None, :, j, :]
            acc += bu[:, i, None, None, :] * row[None]
        out[..., b0 : b0 + BLOCK] = acc
    return out.transpose(3, 0, 1, 2)


def surface_grid(knots_u, p, knots_v, q, ctrl, us, vs, order, *, planar: bool = False):
    """Mixed partials on the grid ``us x vs``: ``(len(us), len(vs), K, K, dim)``, K = order+1.

    Two BLAS products and nothing else.  First the small contraction over v,
    ``W[i, b, l, :] = sum_j Bv_l[b, j] P[i, j, :]`` (size n x nv x K x dim), then one large
    GEMM of the stacked u-basis ``Bu[(a, k), i]`` with it.  The GEMM writes its output in
    the memory order ``(a, k, b, l, dim)`` (point-major: the natural layout for
    positions), or with ``planar`` in the order ``(k, a, l, dim, b)``, where every partial
    and coordinate is a plane with contiguous rows (what the rational quotient wants).
    The result is a transposed *view* of that block: the big array is written once.
    """
    n, m, dim = ctrl.shape
    k_ = order + 1
    bu = basis_matrix(knots_u, p, n, us, order)  # (K, nu, n)
    bv = basis_matrix(knots_v, q, m, vs, order)  # (K, nv, m)
    nu, nv = bu.shape[1], bv.shape[1]
    by_v = ctrl.transpose(1, 0, 2).reshape(m, n * dim)
    w = (bv.reshape(k_ * nv, m) @ by_v).reshape(k_, nv, n, dim)
    if planar:
        w = w.transpose(2, 0, 3, 1).reshape(n, k_ * dim * nv)
        block = (bu.reshape(k_ * nu, n) @ w).reshape(k_, nu, k_, dim, nv)
        return block.transpose(1, 4, 0, 2, 3)
    w = w.transpose(2, 1, 0, 3).reshape(n, nv * k_ * dim)
    stacked_u = bu.transpose(1, 0, 2).reshape(nu * k_, n)
    block = (stacked_u @ w).reshape(nu, k_, nv, k_, dim)
    return block.transpose(0, 2, 1, 3, 4)


def rational_grid_positions(knots_u, p, knots_v, q, hctrl, us, vs, rows: int = 32):
    """Positions of a rational surface on the grid ``us x vs``: ``(len(us), len(vs), 3)``.

    The homogeneous products are formed a few u-rows at a time with the coordinates as
    separate planes, ``H[a, d, b]``, so the division by ``w`` runs over long contiguous
    rows of v and the temporaries stay in cache (a point-major ``(..., 4)`` division is
    three times slower: NumPy's inner loop would be only 3 long).
    """
    n, m, dim = hctrl.shape
    bu = basis_matrix(knots_u, p, n, us)[0]
    bv = basis_matrix(knots_v, q, m, vs)[0]
    nv = bv.shape[0]
    # W[i, d, b] = sum_j Bv[b, j] P[i, j, d]: a GEMM, then one small transposing copy
    by_v = (bv @ hctrl.transpose(1, 0, 2).reshape(m, n * dim)).reshape(nv, n, dim)
    by_v = np.ascontiguousarray(by_v.transpose(1, 2, 0)).reshape(n, dim * nv)
    out = np.empty((bu.shape[0], nv, dim - 1))
    for r0 in range(0, bu.shape[0], rows):
        block = (bu[r0 : r0 + rows] @ by_v).reshape(-1, dim, nv)
        inv_w = 1.0 / block[:, dim - 1]
        for d in range(dim - 1):
            np.multiply(block[:, d], inv_w, out=out[r0 : r0 + rows, :, d])
    return out
