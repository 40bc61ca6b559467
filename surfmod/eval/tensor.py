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


def surface_grid_derivatives(knots_u, p, knots_v, q, ctrl, us, vs, order):
    """Mixed partials on the tensor grid ``us x vs``: ``(len(us), len(vs), order+1, order+1, dim)``.

    Two dense matrix products per derivative pair (BLAS), the fast path for meshes.
    """
    n, m, dim = ctrl.shape
    bu = basis_matrix(knots_u, p, n, us, order)  # (K, nu, n)
    bv = basis_matrix(knots_v, q, m, vs, order)  # (K, nv, m)
    out = np.empty((bu.shape[1], bv.shape[1], order + 1, order + 1, dim))
    for k in range(order + 1):
        tmp = np.tensordot(bu[k], ctrl, axes=(1, 0))  # (nu, m, dim)
        tmp = np.ascontiguousarray(tmp.transpose(0, 2, 1))  # (nu, dim, m)
        for l in range(order + 1):
            out[:, :, k, l, :] = (tmp @ bv[l].T).transpose(0, 2, 1)
    return out
