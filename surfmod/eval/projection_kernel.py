"""The compiled (numba) twins of the closest-point family of :mod:`surfmod.ops.closest`:
:func:`grid_seeds_compiled` (Newton starts by branch and bound over the sampled grid's
cells: the exact ``k`` nearest triangles), :func:`newton_in_boxes_compiled` and
:func:`project_distances_compiled` (the meshers' deviation bounds, batched by
:mod:`surfmod.eval.packed`).

Each is the ``_compiled`` twin of the NumPy function of the same name, held to the same
answers by ``tests/test_ops_nearest.py`` and ``tests/test_projection_kernel.py``.
See :doc:`/design_eval` (section "The compiled paths").
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .kernels import basis_ders_point, find_span_bucketed, position_at, quotient_point

#: Gauss-Newton iterations per point (as ``project_distances``)
ITERATIONS = 6


@njit(cache=True, inline="always", error_model="numpy")
def wrap_parameter(x, lo, hi, period, periodic):
    """OCCT's parameter: periodic directions wrap into the period, others clamp."""
    if periodic:
        return lo + np.mod(x - lo, period)
    return min(max(x, lo), hi)


@njit(cache=True, error_model="numpy")
def project_distances_compiled(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, lo, hi, period,
                               periodic, box, points, uv, threshold, out, start):
    """Distance bounds from ``points (N, 3)`` to the surface into ``out (N,)``, from the
    guesses ``uv (N, 2)`` clipped to ``box = (u0, u1, v0, v1)``; parameters are mapped as
    OCCT evaluates them (``lo``/``hi``/``period``/``periodic`` per direction).  Every
    iterate is a point of the surface, so the least distance seen is an upper bound.
    Points whose first bound is at most ``start`` are not iterated; the others iterate
    until their bound is within ``threshold``.  ``start`` is always given (``threshold``
    when no other), so that every caller compiles the one signature."""
    first_stop = start
    sc = (np.empty((p + 1, p + 1)), np.empty((q + 1, q + 1)), np.empty(p + 1), np.empty(p + 1), np.empty(p + 1),
          np.empty(q + 1), np.empty(q + 1), np.empty(q + 1), np.empty((2, p + 1)), np.empty((2, q + 1)),
          np.empty((2, 2, 4)), np.empty((2, 4)))
    lu, ru, tu, lv, rv, tv = sc[2], sc[3], sc[4], sc[5], sc[6], sc[7]
    binom = np.array([[1.0, 0.0], [1.0, 1.0]])  # C(k, i) to order 1
    s = np.empty((2, 2, 3))  # S, Su, Sv at [0, 0], [1, 0], [0, 1]
    u0, u1, v0, v1 = box[0], box[1], box[2], box[3]
    step_u, step_v = 0.25 * (u1 - u0), 0.25 * (v1 - v0)
    for a in range(points.shape[0]):
        px, py, pz = points[a, 0], points[a, 1], points[a, 2]
        ua, va = min(max(uv[a, 0], u0), u1), min(max(uv[a, 1], v0), v1)
        x, y, z = position_at(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v,
                            wrap_parameter(ua, lo[0], hi[0], period[0], periodic[0]),
                            wrap_parameter(va, lo[1], hi[1], period[1], periodic[1]), lu, ru, tu, lv, rv, tv)
        best = np.sqrt((px - x) ** 2 + (py - y) ** 2 + (pz - z) ** 2)
        active = best > first_stop
        if active:
            for _ in range(ITERATIONS):
                _eval(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v,
                      wrap_parameter(ua, lo[0], hi[0], period[0], periodic[0]), wrap_parameter(va, lo[1], hi[1], period[1], periodic[1]),
                      1, binom, sc, s)
                rx, ry, rz = px - s[0, 0, 0], py - s[0, 0, 1], pz - s[0, 0, 2]
                best = min(best, np.sqrt(rx * rx + ry * ry + rz * rz))
                aa = s[1, 0, 0] * s[1, 0, 0] + s[1, 0, 1] * s[1, 0, 1] + s[1, 0, 2] * s[1, 0, 2]
                bb = s[1, 0, 0] * s[0, 1, 0] + s[1, 0, 1] * s[0, 1, 1] + s[1, 0, 2] * s[0, 1, 2]
                cc = s[0, 1, 0] * s[0, 1, 0] + s[0, 1, 1] * s[0, 1, 1] + s[0, 1, 2] * s[0, 1, 2]
                g1 = s[1, 0, 0] * rx + s[1, 0, 1] * ry + s[1, 0, 2] * rz
                g2 = s[0, 1, 0] * rx + s[0, 1, 1] * ry + s[0, 1, 2] * rz
                det = aa * cc - bb * bb + 1e-14 * (aa + cc) ** 2 + 2.2250738585072014e-308
                dn = min(max((cc * g1 - bb * g2) / det, -step_u), step_u)
                dm = min(max((aa * g2 - bb * g1) / det, -step_v), step_v)
                un, vn = min(max(ua + dn, u0), u1), min(max(va + dm, v0), v1)
                ex = (un - ua) * s[1, 0, 0] + (vn - va) * s[0, 1, 0]
                ey = (un - ua) * s[1, 0, 1] + (vn - va) * s[0, 1, 1]
                ez = (un - ua) * s[1, 0, 2] + (vn - va) * s[0, 1, 2]
                moving = np.sqrt(ex * ex + ey * ey + ez * ez) > 1e-3 * best and best > threshold
                ua, va = un, vn
                if not moving:  # converged, or within the threshold: the bound is in ``best``
                    active = False
                    break
        if active:  # still moving after the last iteration: its last iterate counts too
            x, y, z = position_at(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v,
                                wrap_parameter(ua, lo[0], hi[0], period[0], periodic[0]),
                                wrap_parameter(va, lo[1], hi[1], period[1], periodic[1]), lu, ru, tu, lv, rv, tv)
            best = min(best, np.sqrt((px - x) ** 2 + (py - y) ** 2 + (pz - z) ** 2))
        out[a] = best


@njit(cache=True, inline="always", error_model="numpy")
def _foot(px, py, pz, g, i, j, e, gram, cross, t):
    """Clipped barycentric foot of the point on triangle ``t`` (0 or 1) of cell ``(i, j)``:
    ``(squared distance, beta, gamma)`` (the formula of the NumPy seeding)."""
    ax, ay, az = px - g[i, j, 0], py - g[i, j, 1], pz - g[i, j, 2]
    e0, e1 = 2 * t, 2 * t + 1
    r0 = ax * e[i, j, e0, 0] + ay * e[i, j, e0, 1] + az * e[i, j, e0, 2]
    r1 = ax * e[i, j, e1, 0] + ay * e[i, j, e1, 1] + az * e[i, j, e1, 2]
    d00, d11, d01 = gram[i, j, e0], gram[i, j, e1], cross[i, j, t]
    det = max(d00 * d11 - d01 * d01, 1e-300)
    beta = min(max((d11 * r0 - d01 * r1) / det, 0.0), 1.0)
    gamma = min(max((d00 * r1 - d01 * r0) / det, 0.0), 1.0)
    over = max(beta + gamma, 1.0)
    beta /= over
    gamma /= over
    fx = beta * e[i, j, e0, 0] + gamma * e[i, j, e1, 0] - ax
    fy = beta * e[i, j, e0, 1] + gamma * e[i, j, e1, 1] - ay
    fz = beta * e[i, j, e0, 2] + gamma * e[i, j, e1, 2] - az
    return fx * fx + fy * fy + fz * fz, beta, gamma


@njit(cache=True, inline="always", error_model="numpy")
def _insert(dist, key, vals, d, k, v0, v1, v2, count):
    """Insert ``(d, k, (v0, v1, v2))`` into the sorted top list; returns the new count."""
    size = dist.size
    if count == size and d >= dist[size - 1]:
        return count
    for s in range(count):  # the same triangle already listed (the first cells go twice)
        if key[s] == k:
            return count
    pos = count if count < size else size - 1
    while pos > 0 and dist[pos - 1] > d:
        if pos < size:
            dist[pos] = dist[pos - 1]
            key[pos] = key[pos - 1]
            vals[pos, 0], vals[pos, 1], vals[pos, 2] = vals[pos - 1, 0], vals[pos - 1, 1], vals[pos - 1, 2]
        pos -= 1
    dist[pos] = d
    key[pos] = k
    vals[pos, 0], vals[pos, 1], vals[pos, 2] = v0, v1, v2
    return min(count + 1, size)


@njit(cache=True, inline="always", error_model="numpy")
def _is_bottom(d2, i, j, d):
    """No neighbour of sample ``(i, j)`` (of eight) is nearer than ``d``; the neighbours
    along the row go first, as they reject most samples at once."""
    nu, nv = d2.shape[0], d2.shape[1]
    if j > 0 and d2[i, j - 1] < d:
        return False
    if j < nv - 1 and d2[i, j + 1] < d:
        return False
    j0, j1 = max(j - 1, 0), min(j + 1, nv - 1)
    if i > 0:
        for jj in range(j0, j1 + 1):
            if d2[i - 1, jj] < d:
                return False
    if i < nu - 1:
        for jj in range(j0, j1 + 1):
            if d2[i + 1, jj] < d:
                return False
    return True


@njit(cache=True, error_model="numpy")
def grid_seeds_compiled(points, g, us, vs, e, gram, cross, diam, row_diam, seeds, n_basins, out):
    """Starts ``out (N, seeds + n_basins, 2)``: the ``seeds`` nearest triangles entered at
    their clipped feet, then the ``n_basins`` deepest bottoms of the sampled distance
    (samples no farther than their eight neighbours); short lists repeat their first."""
    nu, nv = g.shape[0], g.shape[1]
    d2 = np.empty((nu, nv))
    row_min = np.empty(nu)
    top_d, top_k, top_v = np.empty(seeds), np.empty(seeds, np.int64), np.empty((seeds, 3))
    bot_d, bot_k, bot_v = np.empty(n_basins), np.empty(n_basins, np.int64), np.empty((n_basins, 3))
    for a in range(points.shape[0]):
        px, py, pz = points[a, 0], points[a, 1], points[a, 2]
        best, bi, bj = np.inf, 0, 0
        for i in range(nu):
            for j in range(nv):
                dx, dy, dz = g[i, j, 0] - px, g[i, j, 1] - py, g[i, j, 2] - pz
                d2[i, j] = dx * dx + dy * dy + dz * dz
        for i in range(nu):
            low = np.inf
            for j in range(nv):
                if d2[i, j] < low:
                    low = d2[i, j]
                    if low < best:
                        best, bi, bj = low, i, j
            row_min[i] = low
        count = 0
        # the cells around the nearest sample first: a tight bound from the start
        for ci in range(max(bi - 1, 0), min(bi + 1, nu - 2) + 1):
            for cj in range(max(bj - 1, 0), min(bj + 1, nv - 2) + 1):
                for t in range(2):
                    d, beta, gamma = _foot(px, py, pz, g, ci, cj, e, gram, cross, t)
                    count = _insert(top_d, top_k, top_v, d, (ci * (nv - 1) + cj) * 2 + t, ci, beta, gamma, count)
        worst = np.sqrt(top_d[seeds - 1]) if count == seeds else np.inf
        for ci in range(nu - 1):
            # a whole row of cells whose nearest sample is out of reach is skipped at once
            reach = worst + row_diam[ci]
            if min(row_min[ci], row_min[ci + 1]) > reach * reach:
                continue
            for cj in range(nv - 1):
                reach = worst + diam[ci, cj]
                if min(min(d2[ci, cj], d2[ci + 1, cj]), min(d2[ci + 1, cj + 1], d2[ci, cj + 1])) > reach * reach:
                    continue
                for t in range(2):
                    d, beta, gamma = _foot(px, py, pz, g, ci, cj, e, gram, cross, t)
                    count = _insert(top_d, top_k, top_v, d, (ci * (nv - 1) + cj) * 2 + t, ci, beta, gamma, count)
                worst = np.sqrt(top_d[seeds - 1]) if count == seeds else np.inf
        for s in range(count):
            kk = top_k[s]
            t = kk % 2
            cell = kk // 2
            ci, cj = cell // (nv - 1), cell % (nv - 1)
            beta, gamma = top_v[s, 1], top_v[s, 2]
            w0 = 1.0 - beta - gamma
            if t == 0:  # corners (i,j), (i+1,j), (i+1,j+1)
                out[a, s, 0] = w0 * us[ci] + beta * us[ci + 1] + gamma * us[ci + 1]
                out[a, s, 1] = w0 * vs[cj] + beta * vs[cj] + gamma * vs[cj + 1]
            else:  # corners (i,j), (i+1,j+1), (i,j+1)
                out[a, s, 0] = w0 * us[ci] + beta * us[ci + 1] + gamma * us[ci]
                out[a, s, 1] = w0 * vs[cj] + beta * vs[cj + 1] + gamma * vs[cj + 1]
        for s in range(count, seeds):
            out[a, s, 0], out[a, s, 1] = out[a, 0, 0], out[a, 0, 1]
        # valley bottoms
        nb = 0
        for i in range(nu):
            for j in range(nv):
                d = d2[i, j]
                if nb == n_basins and d >= bot_d[n_basins - 1]:
                    continue
                # the row neighbours reject most samples: tested here, without a call
                if (j > 0 and d2[i, j - 1] < d) or (j < nv - 1 and d2[i, j + 1] < d):
                    continue
                if _is_bottom(d2, i, j, d):
                    nb = _insert(bot_d, bot_k, bot_v, d, i * nv + j, i, j, 0.0, nb)
        if nb == 0:
            bot_v[0, 0], bot_v[0, 1] = bi, bj
            nb = 1
        for s in range(n_basins):
            src = s if s < nb else 0
            out[a, seeds + s, 0] = us[int(bot_v[src, 0])]
            out[a, seeds + s, 1] = vs[int(bot_v[src, 1])]


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
def newton_in_boxes_compiled(ku, p, kv, q, ctrl, rational, inv_u, inv_v, bucket_u, bucket_v, binom2, binom0,
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
