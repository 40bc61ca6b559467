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

    ``L_k = Bu_k @ P`` per coordinate, then one batched product ``Bv_l @ L_k`` whose
    output is already laid out point-major: BLAS does all the work, no gather, no
    per-point Python, and no copy for plain positions.
    """
    n, m, _ = ctrl.shape
    bu = basis_matrix(knots_u, p, n, us, order)  # (K, nu, n)
    bv = basis_matrix(knots_v, q, m, vs, order)  # (K, nv, m)
    ctrl_d = np.ascontiguousarray(np.moveaxis(ctrl, -1, 0))  # (dim, n, m)
    planes = {}
    for k in range(order + 1):
        left = np.matmul(bu[k], ctrl_d).transpose(1, 2, 0)  # (nu, m, dim)
        for l in range(order + 1):
            planes[k, l] = np.matmul(bv[l], left)  # (nu, nv, dim)
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
