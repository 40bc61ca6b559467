"""Curve evaluation: contract basis arrays with (homogeneous) control points.

Control points arrive in homogeneous form: ``(..., 3)`` for polynomial splines or
``(..., 4)`` = ``(w x, w y, w z, w)`` for rational ones.  The result keeps that last axis;
:mod:`surfmod.eval.rational` turns it into Cartesian derivatives.  Surfaces are evaluated
by :mod:`surfmod.eval.local` (NumPy for small work in :mod:`surfmod.eval.scattered`,
compiled kernels for large); the dense BLAS evaluator of the first round is a test
oracle now (``tests/dense_eval.py``).
"""

from __future__ import annotations

import numpy as np

from .basis import basis_derivatives, find_spans


# Scattered points are processed in blocks: the per-block temporaries stay in cache, and
# memory stays bounded for any number of points.
BLOCK = 1 << 14


def curve_derivatives(knots, degree, ctrl, t, order):
    """Derivatives 0..order of a spline curve: ``(len(t), order + 1, dim)``."""
    t = np.asarray(t, dtype=float).ravel()
    planes = np.ascontiguousarray(ctrl.reshape(-1, ctrl.shape[-1]).T)  # (dim, n_points): fast ``take``
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
