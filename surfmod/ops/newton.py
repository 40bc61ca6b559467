"""Compiled projected Newton for closest points on B-spline / NURBS surfaces.

The same iteration as :func:`surfmod.ops.project._newton_in_boxes` (which stays the path
for every other surface), one start at a time in compiled code: per step one evaluation
of the partials to order 2 at one point (local support, :mod:`surfmod.eval.kernels`),
the safeguarded Newton step in the start's box, and backtracking with positions only.
Imported lazily (numba).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..eval.kernels import basis_ders_point, find_span_bucketed, quotient_point


@njit(cache=True, error_model="numpy")
def _eval(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, u, v, order, binom, sc, out):
    """Cartesian partials ``out[k, l]`` with ``k + l <= order`` at one point (the rest of
    the square is left alone); ``sc`` is a tuple of scratch."""
    ndu_u, ndu_v, lu, ru, tu, lv, rv, tv, du, dv, h, row = sc
    n, m = ctrl.shape[0], ctrl.shape[1]
    kk = order + 1
    su = find_span_bucketed(ku, p, n, u, bucket_u[0], bucket_u[1], bucket_u[2])
    sv = find_span_bucketed(kv, q, m, v, bucket_v[0], bucket_v[1], bucket_v[2])
    basis_ders_point(ku, p, su, u, order, inv_u, ndu_u, lu, ru, tu, du)
    basis_ders_point(kv, q, sv, v, order, inv_v, ndu_v, lv, rv, tv, dv)
    for k in range(kk):
        for l in range(kk):
            for d in range(4):
                h[k, l, d] = 0.0
    for i in range(p + 1):
        for l in range(kk):
            for d in range(4):
                row[l, d] = 0.0
        for j in range(q + 1):
            for l in range(kk):
                c = dv[l, j]
                for d in range(4):
                    row[l, d] += c * ctrl[su - p + i, sv - q + j, d]
        for k in range(kk):
            c = du[k, i]
            for l in range(kk - k):
                for d in range(4):
                    h[k, l, d] += c * row[l, d]
    if rational:
        quotient_point(h[:kk, :kk], binom, out)
    else:
        for k in range(kk):
            for l in range(kk - k):
                for d in range(3):
                    out[k, l, d] = h[k, l, d]


@njit(cache=True, error_model="numpy")
def newton_boxes(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, binom2, binom0,
                 points, u, v, u0, u1, v0, v1, span_u, span_v, iterations):
    """Refine every start ``(u[s], v[s])`` towards the closest point to ``points[s]`` inside
    its box ``[u0, u1] x [v0, v1]``, in place."""
    sc = (np.empty((p + 1, p + 1)), np.empty((q + 1, q + 1)), np.empty(p + 1), np.empty(p + 1), np.empty(p + 1),
          np.empty(q + 1), np.empty(q + 1), np.empty(q + 1), np.empty((3, p + 1)), np.empty((3, q + 1)),
          np.empty((3, 3, 4)), np.empty((3, 4)))
    d = np.empty((3, 3, 3))
    d0 = np.empty((1, 1, 3))
    for s in range(points.shape[0]):
        px, py, pz = points[s, 0], points[s, 1], points[s, 2]
        uu, vv = u[s], v[s]
        lo_u, hi_u, lo_v, hi_v = u0[s], u1[s], v0[s], v1[s]
        for _ in range(iterations):
            _eval(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, uu, vv, 2, binom2, sc, d)
            rx, ry, rz = d[0, 0, 0] - px, d[0, 0, 1] - py, d[0, 0, 2] - pz
            gu = rx * d[1, 0, 0] + ry * d[1, 0, 1] + rz * d[1, 0, 2]
            gv = rx * d[0, 1, 0] + ry * d[0, 1, 1] + rz * d[0, 1, 2]
            a = d[1, 0, 0] ** 2 + d[1, 0, 1] ** 2 + d[1, 0, 2] ** 2
            b = d[1, 0, 0] * d[0, 1, 0] + d[1, 0, 1] * d[0, 1, 1] + d[1, 0, 2] * d[0, 1, 2]
            c = d[0, 1, 0] ** 2 + d[0, 1, 1] ** 2 + d[0, 1, 2] ** 2
            huu = a + (rx * d[2, 0, 0] + ry * d[2, 0, 1] + rz * d[2, 0, 2])
            huv = b + (rx * d[1, 1, 0] + ry * d[1, 1, 1] + rz * d[1, 1, 2])
            hvv = c + (rx * d[0, 2, 0] + ry * d[0, 2, 1] + rz * d[0, 2, 2])
            tiny = 1e-300 + 1e-14 * (a + c) ** 2
            # held at a bound, the step is one-dimensional: its own second derivative
            # decides (the 2x2 Hessian may be indefinite through the other direction)
            huu_1d = huu if huu > 1e-14 * (a + c) else a
            hvv_1d = hvv if hvv > 1e-14 * (a + c) else c
            if huu <= 0 or hvv <= 0 or huu * hvv - huv**2 <= tiny:  # indefinite: Gauss-Newton
                huu, huv, hvv = a, b, c
            huu = max(huu, 1e-300 + 1e-14 * (a + c))
            hvv = max(hvv, 1e-300 + 1e-14 * (a + c))
            det = max(huu * hvv - huv**2, tiny)
            du = (-gu * hvv + gv * huv) / det
            dv = (-gv * huu + gu * huv) / det
            fix_u = (uu <= lo_u and gu > 0) or (uu >= hi_u and gu < 0)
            fix_v = (vv <= lo_v and gv > 0) or (vv >= hi_v and gv < 0)
            if fix_u:
                du = 0.0
            elif fix_v:
                du = -gu / max(huu_1d, 1e-300)
            if fix_v:
                dv = 0.0
            elif fix_u:
                dv = -gv / max(hvv_1d, 1e-300)
            du = min(max(du, -0.25 * span_u), 0.25 * span_u)
            dv = min(max(dv, -0.25 * span_v), 0.25 * span_v)
            f0 = rx * rx + ry * ry + rz * rz
            nu = min(max(uu + du, lo_u), hi_u)
            nv = min(max(vv + dv, lo_v), hi_v)
            step = 1.0
            accepted = False
            for _bt in range(8):  # backtracking while the distance grows
                _eval(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, nu, nv, 0, binom0, sc, d0)
                ex, ey, ez = d0[0, 0, 0] - px, d0[0, 0, 1] - py, d0[0, 0, 2] - pz
                if not ex * ex + ey * ey + ez * ez > f0 * (1 + 1e-12) + 1e-300:
                    accepted = True
                    break
                step /= 4
                nu = min(max(uu + step * du, lo_u), hi_u)
                nv = min(max(vv + step * dv, lo_v), hi_v)
            if not accepted:  # no decrease even for a tiny step: converged to round-off
                nu, nv = uu, vv
            moved = max(abs(nu - uu) / span_u, abs(nv - vv) / span_v)
            uu, vv = nu, nv
            if not moved > 1e-10:  # quadratic convergence: the error is ~1e-20 now
                break
        u[s], v[s] = uu, vv
