"""Local-support evaluation in NumPy, for work too small to wait for a compiled kernel.

The compiled kernels (:mod:`surfmod.eval.kernels` and the grid stages) are the fast path
for large work, but a process pays for them once: importing numba and loading the
kernels from its disk cache costs about a second, compiling them into an empty cache
minutes.  A new user's first grid of a few thousand points, or a mesher's few hundred
samples per face, is done here instead in milliseconds, with the same algorithm as the
kernels (each point touches only its ``(p+1) x (q+1)`` poles; a grid contracts the net
rows it needs with the v-basis once, then each u-point combines ``p + 1`` of them) and
the basis of :mod:`surfmod.eval.basis` (The NURBS Book A2.3).  The values agree with the
kernels' to round-off (a few ulps: the kernels multiply by reciprocal knot differences
where A2.3 divides); :mod:`surfmod.eval.local` chooses the path by the amount of work.

``ctrl`` is the ``(n, m, 4)`` homogeneous net of :class:`surfmod.eval.local.LocalNet`
(the weight column is 1 for a polynomial net and not used).

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


def _basis(knots, degree, n_ctrl, t, order):
    spans = find_spans(knots, degree, n_ctrl, t)
    return spans, basis_derivatives(knots, degree, spans, t, order)  # (N, K, degree+1)


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
        su, bu = _basis(ku, p, n, ub, order)
        sv, bv = _basis(kv, q, m, vb, order)
        h = np.zeros((ub.size, kk, kk, dim))
        for i in range(p + 1):
            # row[a, l] = sum_j d^l Nv_j(v_a) P[su_a - p + i, sv_a - q + j]
            row = np.zeros((ub.size, kk, dim))
            for j in range(q + 1):
                row += bv[:, :, j, None] * ctrl[su - p + i, sv - q + j, None, :dim]
            h += bu[:, :, i, None, None] * row[:, None]
        out[a0 : a0 + BLOCK] = _cartesian(h, rational)
    return out


def grid(ku, p, kv, q, ctrl, rational: bool, us, vs, order: int) -> np.ndarray:
    """Partials to ``order`` on the grid ``us x vs``: ``(len(us), len(vs), K, K, 3)``.

    Two stages, as the compiled grid: the net rows the u-points read are contracted with
    the v-basis once (``rows[r, b, l]``), then every u-point combines its ``p + 1`` rows."""
    n, m = ctrl.shape[:2]
    kk, dim = order + 1, 4 if rational else 3
    su, bu = _basis(ku, p, n, us, order)
    sv, bv = _basis(kv, q, m, vs, order)
    needed = np.unique((su[:, None] - p + np.arange(p + 1)).ravel())
    local = ctrl[needed][:, :, :dim]  # (R, m, dim): only the rows in use
    rows = np.zeros((needed.size, vs.size, kk, dim))
    for j in range(q + 1):
        rows += bv[None, :, :, j, None] * local[:, sv - q + j, None, :]
    first = np.searchsorted(needed, su - p)
    h = np.zeros((us.size, vs.size, kk, kk, dim))
    for i in range(p + 1):
        h += bu[:, None, :, None, i, None] * rows[first + i][:, :, None, :, :]
    return _cartesian(h, rational)
