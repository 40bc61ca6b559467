"""Scattered local-support evaluation in NumPy, for work too small to wait for a compiled
kernel: the twin of :mod:`surfmod.eval.scattered_compiled`, with the same algorithm and
values equal to round-off (:mod:`surfmod.eval.tensor_grid` is its grid).

``ctrl`` is the ``(n, m, 4)`` homogeneous net of :class:`surfmod.eval.local.LocalNet`
(the weight column is 1 for a polynomial net and not used).  See :doc:`/design_eval`.

>>> import numpy as np
>>> net = np.ones((4, 4, 4)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]; net[..., 2] = 0
>>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
>>> scattered(knots, 3, knots, 3, net, False, np.array([0.5]), np.array([0.25]), 0)[:, 0, 0]
array([[1.5 , 0.75, 0.  ]])
"""

from __future__ import annotations

import numpy as np

from .basis import basis_derivatives, find_spans
from .rational import surface_quotient

#: scattered points per block: the per-block temporaries stay in cache
BLOCK = 1 << 13


def basis_at(knots, degree, n_ctrl, t, order):
    """Spans and basis derivatives ``(N, K, degree+1)`` at the parameters ``t``, C-contiguous
    (the compiled grid reads them too)."""
    spans = find_spans(knots, degree, n_ctrl, t)
    return spans, np.ascontiguousarray(basis_derivatives(knots, degree, spans, t, order))


def _cartesian(h: np.ndarray, rational: bool) -> np.ndarray:
    """Homogeneous partials ``(..., K, K, 4 or 3)`` -> Cartesian ``(..., K, K, 3)``."""
    return surface_quotient(h) if rational else h


def scattered(ku, p, kv, q, ctrl, rational: bool, u, v, order: int) -> np.ndarray:
    """Partials to ``order`` at the pairs ``(u[a], v[a])``: ``(N, K, K, 3)``, ``K = order + 1``,
    entry ``[a, k, l]`` = d^(k+l) S / du^k dv^l."""
    n, m = ctrl.shape[:2]
    kk, dim = order + 1, 4 if rational else 3
    out = np.empty((u.size, kk, kk, 3))
    for a0 in range(0, u.size, BLOCK):  # loop over cache blocks, not points
        ub, vb = u[a0 : a0 + BLOCK], v[a0 : a0 + BLOCK]
        su, bu = basis_at(ku, p, n, ub, order)
        sv, bv = basis_at(kv, q, m, vb, order)
        h = np.zeros((ub.size, kk, kk, dim))
        for i in range(p + 1):
            # row[a, l] = sum_j d^l Nv_j(v_a) P[su_a - p + i, sv_a - q + j]
            row = np.zeros((ub.size, kk, dim))
            for j in range(q + 1):
                row += bv[:, :, j, None] * ctrl[su - p + i, sv - q + j, None, :dim]
            h += bu[:, :, i, None, None] * row[:, None]
        out[a0 : a0 + BLOCK] = _cartesian(h, rational)
    return out
