"""The combine stage of the grid (:mod:`surfmod.eval.tensor_grid_compiled`) for positions at
degrees up to 3 in u: each u-point combines its rows of the ring with the v-points
on the vector axis, divides by the weight and stores its points interleaved, all in one
loop with everything in registers (the four row terms are written out; missing ones get
weight 0 on a valid row).

Two u-points go in one pass when they share rows: the same rows (many points a span: a
small net), or, cubic, rows shifted by one (consecutive spans: a big net), where the pair
loads five rows instead of eight.  Each point's sums are those of the one-point pass,
term for term, so the values do not depend on the pairing.
"""

from __future__ import annotations

from numba import njit, uint64

from .kernels import U1, U2, U3


@njit(cache=True, inline="always", error_model="numpy")
def pass_extent(first, p, a, a_end):
    """The u-points of the pass at ``a`` (1 or 2) and the highest row it reads: a pair on
    the same rows, a cubic pair on rows shifted by one, or one point."""
    if a + 1 < a_end and first[a + 1] == first[a]:
        return 2, first[a] + p
    if p == 3 and a + 1 < a_end and first[a + 1] == first[a] + 1:
        return 2, first[a] + 4
    return 1, first[a] + p


@njit(cache=True, inline="always", error_model="numpy")
def positions_pass(bu, first, p, w, rational, b0, out, a, a_end, modulus, count):
    """One pass at u-point ``a`` (u-points up to ``a_end``): ``out[a, b0 + b] = sum_i
    bu[a, 0, i] w[(first[a] + i) % modulus, 0, :3, b]`` (divided by the weight row ``d =
    3`` when ``rational``) for ``b < count``, ``w`` the ring ``(modulus, 1, dim, chunk)``,
    ``out`` point-major; a second u-point too when it shares rows (:func:`pass_extent`).
    Returns the number of u-points done."""
    done, _ = pass_extent(first, p, a, a_end)
    if done == 2 and first[a + 1] == first[a]:  # two u-points on the same rows
        _low_degree_pair(bu, first, p, w, rational, b0, out, a, modulus, count)
        return 2
    if done == 2:  # cubic, consecutive spans
        _shifted_pair(bu, first, w, rational, b0, out, a, modulus, count)
        return 2
    f = first[a]
    c0 = bu[a, 0, 0]
    c1 = bu[a, 0, 1] if p >= 1 else 0.0
    c2 = bu[a, 0, 2] if p >= 2 else 0.0
    c3 = bu[a, 0, 3] if p >= 3 else 0.0
    r0, r1, r2, r3 = f % modulus, (f + min(1, p)) % modulus, (f + min(2, p)) % modulus, (f + min(3, p)) % modulus
    x0, x1, x2, x3 = w[r0, 0, 0], w[r1, 0, 0], w[r2, 0, 0], w[r3, 0, 0]
    y0, y1, y2, y3 = w[r0, 0, 1], w[r1, 0, 1], w[r2, 0, 1], w[r3, 0, 1]
    z0, z1, z2, z3 = w[r0, 0, 2], w[r1, 0, 2], w[r2, 0, 2], w[r3, 0, 2]
    row = out[a].reshape(-1)  # flat, unsigned offsets: no wraparound select, the loop vectorizes
    o = uint64(3 * b0)
    if rational:
        h0, h1, h2, h3 = w[r0, 0, 3], w[r1, 0, 3], w[r2, 0, 3], w[r3, 0, 3]
        for b in range(count):
            ub = uint64(b)
            inv_w = 1.0 / (c0 * h0[ub] + c1 * h1[ub] + c2 * h2[ub] + c3 * h3[ub])
            t = o + U3 * ub
            row[t] = (c0 * x0[ub] + c1 * x1[ub] + c2 * x2[ub] + c3 * x3[ub]) * inv_w
            row[t + U1] = (c0 * y0[ub] + c1 * y1[ub] + c2 * y2[ub] + c3 * y3[ub]) * inv_w
            row[t + U2] = (c0 * z0[ub] + c1 * z1[ub] + c2 * z2[ub] + c3 * z3[ub]) * inv_w
    else:
        for b in range(count):
            ub = uint64(b)
            t = o + U3 * ub
            row[t] = c0 * x0[ub] + c1 * x1[ub] + c2 * x2[ub] + c3 * x3[ub]
            row[t + U1] = c0 * y0[ub] + c1 * y1[ub] + c2 * y2[ub] + c3 * y3[ub]
            row[t + U2] = c0 * z0[ub] + c1 * z1[ub] + c2 * z2[ub] + c3 * z3[ub]
    return 1


@njit(cache=True, inline="always", error_model="numpy")
def _low_degree_pair(bu, first, p, w, rational, b0, out, a, modulus, count):
    """u-points ``a`` and ``a + 1`` of :func:`positions_pass` when they share their
    rows (same span): one pass loads each row value once for both (the arithmetic of
    each point is that of the single pass, so the values are the same)."""
    f = first[a]
    r0, r1, r2, r3 = f % modulus, (f + min(1, p)) % modulus, (f + min(2, p)) % modulus, (f + min(3, p)) % modulus
    c0, e0 = bu[a, 0, 0], bu[a + 1, 0, 0]
    c1, e1 = (bu[a, 0, 1], bu[a + 1, 0, 1]) if p >= 1 else (0.0, 0.0)
    c2, e2 = (bu[a, 0, 2], bu[a + 1, 0, 2]) if p >= 2 else (0.0, 0.0)
    c3, e3 = (bu[a, 0, 3], bu[a + 1, 0, 3]) if p >= 3 else (0.0, 0.0)
    x0, x1, x2, x3 = w[r0, 0, 0], w[r1, 0, 0], w[r2, 0, 0], w[r3, 0, 0]
    y0, y1, y2, y3 = w[r0, 0, 1], w[r1, 0, 1], w[r2, 0, 1], w[r3, 0, 1]
    z0, z1, z2, z3 = w[r0, 0, 2], w[r1, 0, 2], w[r2, 0, 2], w[r3, 0, 2]
    row, nxt = out[a].reshape(-1), out[a + 1].reshape(-1)
    o = uint64(3 * b0)
    if rational:
        h0, h1, h2, h3 = w[r0, 0, 3], w[r1, 0, 3], w[r2, 0, 3], w[r3, 0, 3]
        for b in range(count):
            ub = uint64(b)
            t = o + U3 * ub
            vx0, vx1, vx2, vx3 = x0[ub], x1[ub], x2[ub], x3[ub]
            vy0, vy1, vy2, vy3 = y0[ub], y1[ub], y2[ub], y3[ub]
            vz0, vz1, vz2, vz3 = z0[ub], z1[ub], z2[ub], z3[ub]
            vw0, vw1, vw2, vw3 = h0[ub], h1[ub], h2[ub], h3[ub]
            inv_w = 1.0 / (c0 * vw0 + c1 * vw1 + c2 * vw2 + c3 * vw3)
            row[t] = (c0 * vx0 + c1 * vx1 + c2 * vx2 + c3 * vx3) * inv_w
            row[t + U1] = (c0 * vy0 + c1 * vy1 + c2 * vy2 + c3 * vy3) * inv_w
            row[t + U2] = (c0 * vz0 + c1 * vz1 + c2 * vz2 + c3 * vz3) * inv_w
            inv_w = 1.0 / (e0 * vw0 + e1 * vw1 + e2 * vw2 + e3 * vw3)
            nxt[t] = (e0 * vx0 + e1 * vx1 + e2 * vx2 + e3 * vx3) * inv_w
            nxt[t + U1] = (e0 * vy0 + e1 * vy1 + e2 * vy2 + e3 * vy3) * inv_w
            nxt[t + U2] = (e0 * vz0 + e1 * vz1 + e2 * vz2 + e3 * vz3) * inv_w
    else:
        for b in range(count):
            ub = uint64(b)
            t = o + U3 * ub
            vx0, vx1, vx2, vx3 = x0[ub], x1[ub], x2[ub], x3[ub]
            vy0, vy1, vy2, vy3 = y0[ub], y1[ub], y2[ub], y3[ub]
            vz0, vz1, vz2, vz3 = z0[ub], z1[ub], z2[ub], z3[ub]
            row[t] = c0 * vx0 + c1 * vx1 + c2 * vx2 + c3 * vx3
            row[t + U1] = c0 * vy0 + c1 * vy1 + c2 * vy2 + c3 * vy3
            row[t + U2] = c0 * vz0 + c1 * vz1 + c2 * vz2 + c3 * vz3
            nxt[t] = e0 * vx0 + e1 * vx1 + e2 * vx2 + e3 * vx3
            nxt[t + U1] = e0 * vy0 + e1 * vy1 + e2 * vy2 + e3 * vy3
            nxt[t + U2] = e0 * vz0 + e1 * vz1 + e2 * vz2 + e3 * vz3


@njit(cache=True, inline="always", error_model="numpy")
def _shifted_pair(bu, first, w, rational, b0, out, a, modulus, count):
    """Cubic u-points ``a`` (rows ``r..r+3``) and ``a + 1`` (rows ``r+1..r+4``) in one
    pass: five rows loaded for both instead of eight (each point's sums are those of the
    one-point pass, term for term).  The rows are read through one flat view of the
    ring by offsets: twenty views would need more runtime alias checks than LLVM allows
    a vectorized loop."""
    c0, c1, c2, c3 = bu[a, 0, 0], bu[a, 0, 1], bu[a, 0, 2], bu[a, 0, 3]
    e0, e1, e2, e3 = bu[a + 1, 0, 0], bu[a + 1, 0, 1], bu[a + 1, 0, 2], bu[a + 1, 0, 3]
    f = first[a]
    f0, f1, f2 = w[f % modulus, 0].reshape(-1), w[(f + 1) % modulus, 0].reshape(-1), w[(f + 2) % modulus, 0].reshape(-1)
    f3, f4 = w[(f + 3) % modulus, 0].reshape(-1), w[(f + 4) % modulus, 0].reshape(-1)
    unv = uint64(w.shape[3])  # plane stride within a row
    row, nxt = out[a].reshape(-1), out[a + 1].reshape(-1)
    o = uint64(3 * b0)
    if rational:
        for b in range(count):
            ub = uint64(b)
            t = o + U3 * ub
            vx0, vx1, vx2, vx3, vx4 = f0[ub], f1[ub], f2[ub], f3[ub], f4[ub]
            y = ub + unv
            vy0, vy1, vy2, vy3, vy4 = f0[y], f1[y], f2[y], f3[y], f4[y]
            z = y + unv
            vz0, vz1, vz2, vz3, vz4 = f0[z], f1[z], f2[z], f3[z], f4[z]
            h = z + unv
            vw0, vw1, vw2, vw3, vw4 = f0[h], f1[h], f2[h], f3[h], f4[h]
            inv_w = 1.0 / (c0 * vw0 + c1 * vw1 + c2 * vw2 + c3 * vw3)
            row[t] = (c0 * vx0 + c1 * vx1 + c2 * vx2 + c3 * vx3) * inv_w
            row[t + U1] = (c0 * vy0 + c1 * vy1 + c2 * vy2 + c3 * vy3) * inv_w
            row[t + U2] = (c0 * vz0 + c1 * vz1 + c2 * vz2 + c3 * vz3) * inv_w
            inv_w = 1.0 / (e0 * vw1 + e1 * vw2 + e2 * vw3 + e3 * vw4)
            nxt[t] = (e0 * vx1 + e1 * vx2 + e2 * vx3 + e3 * vx4) * inv_w
            nxt[t + U1] = (e0 * vy1 + e1 * vy2 + e2 * vy3 + e3 * vy4) * inv_w
            nxt[t + U2] = (e0 * vz1 + e1 * vz2 + e2 * vz3 + e3 * vz4) * inv_w
    else:
        for b in range(count):
            ub = uint64(b)
            t = o + U3 * ub
            vx0, vx1, vx2, vx3, vx4 = f0[ub], f1[ub], f2[ub], f3[ub], f4[ub]
            y = ub + unv
            vy0, vy1, vy2, vy3, vy4 = f0[y], f1[y], f2[y], f3[y], f4[y]
            z = y + unv
            vz0, vz1, vz2, vz3, vz4 = f0[z], f1[z], f2[z], f3[z], f4[z]
            row[t] = c0 * vx0 + c1 * vx1 + c2 * vx2 + c3 * vx3
            row[t + U1] = c0 * vy0 + c1 * vy1 + c2 * vy2 + c3 * vy3
            row[t + U2] = c0 * vz0 + c1 * vz1 + c2 * vz2 + c3 * vz3
            nxt[t] = e0 * vx1 + e1 * vx2 + e2 * vx3 + e3 * vx4
            nxt[t + U1] = e0 * vy1 + e1 * vy2 + e2 * vy3 + e3 * vy4
            nxt[t + U2] = e0 * vz1 + e1 * vz2 + e2 * vz3 + e3 * vz4
