"""Tensor-product evaluation: contract basis arrays with (homogeneous) control points.

Control points arrive in homogeneous form: ``(..., 3)`` for polynomial splines or
``(..., 4)`` = ``(w x, w y, w z, w)`` for rational ones.  The result keeps that last axis;
:mod:`surfmod.eval.rational` turns it into Cartesian derivatives.
"""

from __future__ import annotations

import numpy as np

from .basis import basis_derivatives, basis_matrix, find_spans


def curve_derivatives(knots, degree, ctrl, t, order):
    """Derivatives 0..order of a spline curve: ``(len(t), order + 1, dim)``."""
    t = np.asarray(t, dtype=float).ravel()
    spans = find_spans(knots, degree, ctrl.shape[0], t)
    ders = basis_derivatives(knots, degree, spans, t, order)
    idx = spans[:, None] - degree + np.arange(degree + 1)[None, :]
    local = ctrl[idx]  # (N, p+1, dim)
    return np.einsum("nkp,npd->nkd", ders, local)


def surface_derivatives(knots_u, p, knots_v, q, ctrl, u, v, order):
    """Mixed partials up to ``order`` at scattered pairs: ``(N, order+1, order+1, dim)``.

    Entry ``[a, k, l]`` is d^(k+l) S / du^k dv^l at ``(u[a], v[a])``.
    """
    u = np.asarray(u, dtype=float).ravel()
    v = np.asarray(v, dtype=float).ravel()
    n, m = ctrl.shape[:2]
    su = find_spans(knots_u, p, n, u)
    sv = find_spans(knots_v, q, m, v)
    nu = basis_derivatives(knots_u, p, su, u, order)
    nv = basis_derivatives(knots_v, q, sv, v, order)
    iu = su[:, None] - p + np.arange(p + 1)[None, :]
    iv = sv[:, None] - q + np.arange(q + 1)[None, :]
    local = ctrl[iu[:, :, None], iv[:, None, :]]  # (N, p+1, q+1, dim)
    tmp = np.einsum("nki,nijd->nkjd", nu, local)
    return np.einsum("nkjd,nlj->nkld", tmp, nv)


def surface_grid_planes(knots_u, p, knots_v, q, ctrl, us, vs, order):
    """Mixed partials on the grid ``us x vs``: ``{(k, l): array (len(us), len(vs), dim)}``.

    First the small contraction over v, ``W_l[i, b, :] = sum_j Bv_l[b, j] P[i, j, :]``
    (size n x nv x dim), then one large GEMM ``Bu_k @ W_l`` whose output is already the
    point-major grid: BLAS does all the work, nothing is gathered or copied afterwards.
    """
    n, m, dim = ctrl.shape
    bu = basis_matrix(knots_u, p, n, us, order)  # (K, nu, n)
    bv = basis_matrix(knots_v, q, m, vs, order)  # (K, nv, m)
    nu, nv = bu.shape[1], bv.shape[1]
    by_v = ctrl.transpose(1, 0, 2).reshape(m, n * dim)
    planes = {}
    for l in range(order + 1):
        w = (bv[l] @ by_v).reshape(nv, n, dim).transpose(1, 0, 2).reshape(n, nv * dim)
        for k in range(order + 1):
            planes[k, l] = (bu[k] @ w).reshape(nu, nv, dim)
    return planes


def planes_to_array(planes, order, dim=3):
    """Assemble ``{(k, l): (nu, nv, dim)}`` into ``(nu, nv, order+1, order+1, dim)``
    (a view, without copying, for positions only)."""
    if order == 0:
        return planes[0, 0][:, :, None, None, :dim]
    first = planes[0, 0]
    out = np.empty((first.shape[0], first.shape[1], order + 1, order + 1, dim))
    for (k, l), plane in planes.items():
        out[:, :, k, l, :] = plane[..., :dim]
    return out
