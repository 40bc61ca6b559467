"""Compiled (numba) distance bounds from points to a B-spline surface by damped
Gauss-Newton: :func:`surfmod.meshing.deviation.project_distances` for a net the kernels
of :mod:`surfmod.eval.kernels` evaluate, point by point in one call.

The same iteration (guesses clipped to the box, steps limited to a quarter of it, the
3-D step below 1e-3 of the distance or the bound within the threshold ends it), so the
values equal the NumPy path's to round-off.  Measuring a real part's B-spline faces
projects a few hundred samples per face; in NumPy each of the six iterations is a
dozen array calls on those few points, which cost more than the arithmetic.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .kernels import basis_ders_point, find_span_bucketed, position_at

#: Gauss-Newton iterations per point (as ``project_distances``)
ITERATIONS = 6


@njit(cache=True, inline="always", error_model="numpy")
def _wrap(x, lo, hi, period, periodic):
    """OCCT's parameter: periodic directions wrap into the period, others clamp."""
    if periodic:
        return lo + np.mod(x - lo, period)
    return min(max(x, lo), hi)


@njit(cache=True, error_model="numpy")
def _first_partials(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, u, v, ndu_u, ndu_v, lu, ru, tu,
                    lv, rv, tv, du, dv, h, out):
    """``out[0]`` S, ``out[1]`` Su, ``out[2]`` Sv (Cartesian: the quotient rule applied)."""
    n, m = ctrl.shape[0], ctrl.shape[1]
    su = find_span_bucketed(ku, p, n, u, bucket_u[0], bucket_u[1], bucket_u[2])
    sv = find_span_bucketed(kv, q, m, v, bucket_v[0], bucket_v[1], bucket_v[2])
    basis_ders_point(ku, p, su, u, 1, inv_u, ndu_u, lu, ru, tu, du)
    basis_ders_point(kv, q, sv, v, 1, inv_v, ndu_v, lv, rv, tv, dv)
    h[:, :] = 0.0
    for i in range(p + 1):
        ci = su - p + i
        for j in range(q + 1):
            cj = sv - q + j
            b00, b10, b01 = du[0, i] * dv[0, j], du[1, i] * dv[0, j], du[0, i] * dv[1, j]
            for d in range(4):
                c = ctrl[ci, cj, d]
                h[0, d] += b00 * c
                h[1, d] += b10 * c
                h[2, d] += b01 * c
    w = h[0, 3] if rational else 1.0
    for d in range(3):
        out[0, d] = h[0, d] / w
    for k in range(1, 3):
        wk = h[k, 3] if rational else 0.0
        for d in range(3):
            out[k, d] = (h[k, d] - wk * out[0, d]) / w


@njit(cache=True, error_model="numpy")
def project_distances(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, lo, hi, period, periodic, box,
                      points, uv, threshold, out, start):
    """Distance bounds from ``points (N, 3)`` to the surface into ``out (N,)``, from the
    guesses ``uv (N, 2)`` clipped to ``box = (u0, u1, v0, v1)``; parameters are mapped as
    OCCT evaluates them (``lo``/``hi``/``period``/``periodic`` per direction).  Every
    iterate is a point of the surface, so the least distance seen is an upper bound.
    Points whose first bound is at most ``start`` are not iterated; the others iterate
    until their bound is within ``threshold``.  ``start`` is always given (``threshold``
    when no other), so that every caller compiles the one signature."""
    first_stop = start
    ndu_u, ndu_v = np.empty((p + 1, p + 1)), np.empty((q + 1, q + 1))
    lu, ru, tu = np.empty(p + 1), np.empty(p + 1), np.empty(p + 1)
    lv, rv, tv = np.empty(q + 1), np.empty(q + 1), np.empty(q + 1)
    du, dv = np.empty((2, p + 1)), np.empty((2, q + 1))
    h, s = np.empty((3, 4)), np.empty((3, 3))
    u0, u1, v0, v1 = box[0], box[1], box[2], box[3]
    step_u, step_v = 0.25 * (u1 - u0), 0.25 * (v1 - v0)
    for a in range(points.shape[0]):
        px, py, pz = points[a, 0], points[a, 1], points[a, 2]
        ua, va = min(max(uv[a, 0], u0), u1), min(max(uv[a, 1], v0), v1)
        x, y, z = position_at(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v,
                            _wrap(ua, lo[0], hi[0], period[0], periodic[0]),
                            _wrap(va, lo[1], hi[1], period[1], periodic[1]), lu, ru, tu, lv, rv, tv)
        best = np.sqrt((px - x) ** 2 + (py - y) ** 2 + (pz - z) ** 2)
        active = best > first_stop
        if active:
            for _ in range(ITERATIONS):
                _first_partials(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v,
                                _wrap(ua, lo[0], hi[0], period[0], periodic[0]),
                                _wrap(va, lo[1], hi[1], period[1], periodic[1]), ndu_u, ndu_v, lu, ru, tu, lv, rv,
                                tv, du, dv, h, s)
                rx, ry, rz = px - s[0, 0], py - s[0, 1], pz - s[0, 2]
                best = min(best, np.sqrt(rx * rx + ry * ry + rz * rz))
                aa = s[1, 0] * s[1, 0] + s[1, 1] * s[1, 1] + s[1, 2] * s[1, 2]
                bb = s[1, 0] * s[2, 0] + s[1, 1] * s[2, 1] + s[1, 2] * s[2, 2]
                cc = s[2, 0] * s[2, 0] + s[2, 1] * s[2, 1] + s[2, 2] * s[2, 2]
                g1 = s[1, 0] * rx + s[1, 1] * ry + s[1, 2] * rz
                g2 = s[2, 0] * rx + s[2, 1] * ry + s[2, 2] * rz
                det = aa * cc - bb * bb + 1e-14 * (aa + cc) ** 2 + 2.2250738585072014e-308
                dn = min(max((cc * g1 - bb * g2) / det, -step_u), step_u)
                dm = min(max((aa * g2 - bb * g1) / det, -step_v), step_v)
                un, vn = min(max(ua + dn, u0), u1), min(max(va + dm, v0), v1)
                ex = (un - ua) * s[1, 0] + (vn - va) * s[2, 0]
                ey = (un - ua) * s[1, 1] + (vn - va) * s[2, 1]
                ez = (un - ua) * s[1, 2] + (vn - va) * s[2, 2]
                moving = np.sqrt(ex * ex + ey * ey + ez * ez) > 1e-3 * best and best > threshold
                ua, va = un, vn
                if not moving:  # converged, or within the threshold: the bound is in ``best``
                    active = False
                    break
        if active:  # still moving after the last iteration: its last iterate counts too
            x, y, z = position_at(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v,
                                _wrap(ua, lo[0], hi[0], period[0], periodic[0]),
                                _wrap(va, lo[1], hi[1], period[1], periodic[1]), lu, ru, tu, lv, rv, tv)
            best = min(best, np.sqrt((px - x) ** 2 + (py - y) ** 2 + (pz - z) ** 2))
        out[a] = best
