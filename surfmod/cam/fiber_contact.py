"""Where along a horizontal line ("fiber") an end mill at tip height ``z`` meets a triangle:
one compiled scalar routine per (fiber, triangle) pair (:func:`pair_intervals`).

Tool and triangle are convex, so the positions where they meet are one interval, whose ends
are closed-form contacts with the triangle's vertices, edges and facet.
See :doc:`/guide/cam` (section "Waterline").

A ball of radius 1 along the x axis under a level triangle 1 above its tip: the
triangle's x range [0, 1] grown by the radius.

>>> import numpy as np
>>> from surfmod.cam.cutters import Ball
>>> rows = triangle_rows(np.array([[[0, -1, 1], [0, 1, 1], [1, 0, 1]]], float))
>>> t0, t1 = pair_intervals(rows, [0], [0.0], [0.0], [1.0], [0.0], 0.0, Ball(1.0))
>>> float(t0[0]), float(t1[0])
(-1.0, 2.0)
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .cutters import Cutter
from .drop_cutter import BALL, triangle_rows

#: Bound on the regula falsi (Illinois) steps of the torus contact: it takes about ten;
#: bisection alone would take an angle bracket of π to rounding in ~55.
TORUS_STEPS = 200


@njit(cache=True, inline="always", error_model="numpy")
def profile_radius(h, R, rc):
    """Tool radius at height ``h`` ≥ 0 above the tip (R above the corner)."""
    if h >= rc:
        return R
    hc = min(max(h, 0.0), rc)
    return R - rc + math.sqrt(max(rc * rc - (rc - hc) * (rc - hc), 0.0))


@njit(cache=True, inline="always", error_model="numpy")
def _disc(span, px, py, radius, ox, oy, dx, dy):
    """The chord of the fiber through the disc of ``radius`` round (px, py)."""
    wx, wy = px - ox, py - oy
    along = wx * dx + wy * dy
    off = wx * dy - wy * dx
    g = radius * radius - off * off
    if g >= 0.0:
        root = math.sqrt(g)
        _add(span, along - root)
        _add(span, along + root)


@njit(cache=True, inline="always", error_model="numpy")
def _add(span, t):
    if t < span[0]:
        span[0] = t
    if t > span[1]:
        span[1] = t


@njit(cache=True, inline="always", error_model="numpy")
def _above(h0, ez, level):
    """Parameter range ``(ua, ub)`` of an edge where its height above z is ≥ ``level``
    (empty: ua > ub)."""
    if abs(ez) < 1e-300:
        return (0.0, 1.0) if h0 >= level else (2.0, -1.0)
    u = (level - h0) / ez
    if ez > 0.0:
        return max(u, 0.0), 1.0
    return 0.0, min(u, 1.0)


@njit(cache=True, inline="always", error_model="numpy")
def _between(h0, ez, rc):
    """Parameter range of an edge whose height above z lies in [0, rc): the range above 0
    minus the range above rc, one piece since the edge is straight."""
    a0, b0 = _above(h0, ez, 0.0)
    a1, b1 = _above(h0, ez, rc)
    if ez > 0.0:
        return a0, min(b0, a1)
    if ez < 0.0:
        return max(a0, b1), b0
    if abs(ez) < 1e-300 and h0 >= rc:
        return a0, -1.0
    return a0, b0


@njit(cache=True, inline="always", error_model="numpy")
def _offset_lines(span, px, py, ex, ey, ua, ub, radius, ox, oy, dx, dy):
    """The fiber's crossings of the two lines at ``radius`` from the edge's (x, y)
    projection, kept within the edge's parameter range [ua, ub]."""
    L = math.hypot(ex, ey)
    if not (ub >= ua and L > 0.0):
        return
    nx, ny = -ey / L, ex / L
    det = -dx * ey + ex * dy  # of [d, -e] (columns)
    if not abs(det) > 1e-14 * L:
        return
    for side in (1.0, -1.0):
        bx = px + side * radius * nx - ox
        by = py + side * radius * ny - oy
        t = (bx * -ey + ex * by) / det
        u = (dx * by - dy * bx) / det
        if ua <= u <= ub:
            _add(span, t)


@njit(cache=True, inline="always", error_model="numpy")
def _ball_edge(span, px, py, pz, ex, ey, ez, uc, ud, z, R, ox, oy, dx, dy):
    """The ball's centre line (height z + R along the fiber) at distance R from the edge's
    line: a quadratic in t, roots kept where the foot lies in [uc, ud]."""
    Le = math.sqrt(ex * ex + ey * ey + ez * ez)
    if not (ud >= uc and Le > 0.0):
        return
    ux, uy, uz = ex / Le, ey / Le, ez / Le
    wx, wy, wz = ox - px, oy - py, z + R - pz
    De = dx * ux + dy * uy
    we = wx * ux + wy * uy + wz * uz
    a = 1.0 - De * De
    b = wx * dx + wy * dy - we * De
    c = wx * wx + wy * wy + wz * wz - we * we - R * R
    disc = b * b - a * c
    if not (a > 1e-14 and disc >= 0.0):
        return
    root = math.sqrt(disc)
    for t in ((-b - root) / a, (-b + root) / a):
        u = (we + t * De) / Le
        if uc <= u <= ud:
            _add(span, t)


@njit(cache=True, inline="always", error_model="numpy")
def _ellipse_offset(th, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy):
    """The point at angle ``th`` of the ellipse (centre c, semi-axes A along u, B across)
    pushed out by ``core`` along its normal: its offset from the fiber (right positive),
    its position along the fiber, and the ellipse point."""
    c, s = math.cos(th), math.sin(th)
    qx = cx + A * c * ux - B * s * uy
    qy = cy + A * c * uy + B * s * ux
    gx, gy = c / A, s / B
    g = math.hypot(gx, gy)
    fx = qx + core * (gx * ux - gy * uy) / g - ox
    fy = qy + core * (gx * uy + gy * ux) / g - oy
    return fx * dy - fy * dx, fx * dx + fy * dy, qx, qy


@njit(cache=True, error_model="numpy")
def _torus_root(lo, hi, flo, fhi, ftol, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy):
    """The angle in [lo, hi] where the monotone offset changes sign (flo, fhi of opposite
    signs): regula falsi with the Illinois halving of the end that stays (superlinear),
    until the offset is within ``ftol`` (its rounding) or the bracket is at rounding."""
    if flo == 0.0 or fhi == 0.0:
        return lo if flo == 0.0 else hi
    side = 0
    mid = 0.5 * (lo + hi)
    for _ in range(TORUS_STEPS):
        if not hi - lo > 4e-16 * max(abs(lo), abs(hi), 1.0):
            break
        mid = lo + (hi - lo) * flo / (flo - fhi)
        if not lo < mid < hi:
            mid = 0.5 * (lo + hi)
        f = _ellipse_offset(mid, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy)[0]
        if abs(f) <= ftol:
            break
        if (f < 0.0) == (flo < 0.0):
            lo, flo = mid, f
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = mid, f
            if side == 1:
                flo *= 0.5
            side = 1
    return mid


@njit(cache=True, error_model="numpy")
def _torus_edge(span, px, py, pz, ex, ey, ez, uc, ud, z, R, rc, ox, oy, dx, dy):
    """The torus end against the edge's part between z and z + rc.

    A level edge (height h in [0, rc)) forbids the band within the profile's radius there
    of its (x, y) projection.  A tilted one is touched when the core circle's centre (at
    height z + rc) lies at distance R - rc outside the ellipse in which the cylinder of
    radius rc round the edge's line cuts that plane: on that ellipse's outer offset, a
    convex curve, which the fiber crosses at most twice.  The offset's extreme points
    across the fiber are where its normal is normal to the fiber (closed form on the
    ellipse's angle); between them the offset is monotone, so each crossing is bracketed
    and found by :func:`_torus_root`.  A crossing counts when its contact (the ellipse
    point's foot on the edge's line) lies in [uc, ud]."""
    if not ud >= uc:
        return
    L = math.sqrt(ex * ex + ey * ey + ez * ez)
    if not abs(ez) > 1e-12 * L:
        _offset_lines(span, px, py, ex, ey, 0.0, 1.0, profile_radius(pz - z, R, rc), ox, oy, dx, dy)
        return
    ax, ay, az = ex / L, ey / L, ez / L
    # the edge line meets the plane z + rc at the ellipse centre
    s0 = (z + rc - pz) / az
    cx, cy = px + s0 * ax, py + s0 * ay
    # semi-axis rc / |a_z| along the line's horizontal direction u, rc across it
    hxy = math.hypot(ax, ay)
    ux, uy = (ax / hxy, ay / hxy) if hxy > 1e-15 else (1.0, 0.0)
    A, B = rc / abs(az), rc
    core = R - rc
    if abs((cx - ox) * dy - (cy - oy) * dx) > A + core:  # the offset lies within A + core of c
        return
    # the fiber's right normal m in the ellipse's frame (u, u⊥): the offset is farthest
    # right where the ellipse's normal (cos/A, sin/B) points along m
    mu, mv = dy * ux - dx * uy, -dy * uy - dx * ux
    top = math.atan2(B * mv, A * mu)
    f_top = _ellipse_offset(top, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy)[0]
    f_bot = _ellipse_offset(top + math.pi, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy)[0]
    if not (f_top >= 0.0 and f_bot <= 0.0):
        return
    # the offset's rounding: a few ulps of the coordinates it is computed from
    ftol = 4e-16 * (abs(cx - ox) + abs(cy - oy) + A + R)
    for lo, hi, flo, fhi in ((top, top + math.pi, f_top, f_bot), (top + math.pi, top + 2.0 * math.pi, f_bot, f_top)):
        th = _torus_root(lo, hi, flo, fhi, ftol, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy)
        _, t, qx, qy = _ellipse_offset(th, cx, cy, A, B, ux, uy, core, ox, oy, dx, dy)
        foot = ((qx - px) * ax + (qy - py) * ay + (z + rc - pz) * az) / L
        if uc <= foot <= ud:
            _add(span, t)


@njit(cache=True, inline="always", error_model="numpy")
def _facet(span, row, z, R, rc, ox, oy, dx, dy):
    """The tool's support point along the facet's upward normal on its plane (the core's rim
    uphill pushed out by ``rc`` along it), kept when it falls inside the triangle."""
    nx, ny, nz = row[9], row[10], row[11]
    sxy = math.hypot(nx, ny)
    if not (nz > 1e-12 and sxy > 1e-15):
        return
    sx, sy = nx / sxy, ny / sxy
    # support point of the tool along -n, relative to the tip at (o + t d, z)
    qx, qy, qz = -(R - rc) * sx - rc * nx, -(R - rc) * sy - rc * ny, rc - rc * nz
    rate = nx * dx + ny * dy
    if not abs(rate) > 1e-15:
        return
    ax, ay, az = row[0], row[1], row[2]
    t = -(nx * (ox + qx - ax) + ny * (oy + qy - ay) + nz * (z + qz - az)) / rate
    cx, cy = ox + t * dx + qx, oy + t * dy + qy
    v0x, v0y, v1x, v1y = row[3] - ax, row[4] - ay, row[6] - ax, row[7] - ay
    den = v0x * v1y - v1x * v0y
    if den == 0.0:
        return
    wx, wy = cx - ax, cy - ay
    l1 = (wx * v1y - v1x * wy) / den
    l2 = (v0x * wy - wx * v0y) / den
    if l1 >= 0.0 and l2 >= 0.0 and l1 + l2 <= 1.0:
        _add(span, t)


@njit(cache=True, error_model="numpy")
def _pair(span, row, ox, oy, dx, dy, z, code, R, rc):
    """The interval of one (fiber, triangle) pair into ``span`` (inf, -inf if none) for the
    cutter ``code`` (the one choice of a cutter's routine here: its rounded end's edge)."""
    span[0], span[1] = np.inf, -np.inf
    core = R - rc
    for j in range(3):
        k, k1 = 3 * j, 3 * ((j + 1) % 3)
        px, py, pz = row[k], row[k + 1], row[k + 2]
        ex, ey, ez = row[k1] - px, row[k1 + 1] - py, row[k1 + 2] - pz
        h0 = pz - z
        if h0 >= 0.0:
            _disc(span, px, py, profile_radius(h0, R, rc), ox, oy, dx, dy)
        # crossings of the heights z and z + rc: points whose disc is the profile's there
        if abs(ez) >= 1e-300:
            u = -h0 / ez
            if 0.0 < u < 1.0:
                _disc(span, px + u * ex, py + u * ey, core if rc > 0.0 else R, ox, oy, dx, dy)
            if rc > 0.0:
                u = (rc - h0) / ez
                if 0.0 < u < 1.0:
                    _disc(span, px + u * ex, py + u * ey, R, ox, oy, dx, dy)
        # the edge's part above z + rc (cylinder) and within [z, z + rc) (the rounded end)
        ua, ub = _above(h0, ez, rc)
        _offset_lines(span, px, py, ex, ey, ua, ub, R, ox, oy, dx, dy)
        if rc > 0.0:
            uc, ud = _between(h0, ez, rc)
            if code == BALL:
                _ball_edge(span, px, py, pz, ex, ey, ez, uc, ud, z, R, ox, oy, dx, dy)
            else:
                _torus_edge(span, px, py, pz, ex, ey, ez, uc, ud, z, R, rc, ox, oy, dx, dy)
    _facet(span, row, z, R, rc, ox, oy, dx, dy)


@njit(cache=True, error_model="numpy")
def _pairs_kernel(rows, ti, ox, oy, dx, dy, z, code, R, rc, t0, t1):
    span = np.empty(2)
    for i in range(len(ti)):
        _pair(span, rows[ti[i]], ox[i], oy[i], dx[i], dy[i], z, code, R, rc)
        t0[i], t1[i] = span[0], span[1]


def pair_intervals(rows, ti, ox, oy, dx, dy, z, cutter: Cutter):
    """``(t0, t1)`` per pair: the triangle ``rows[ti]`` (rows of
    :class:`~surfmod.cam.drop_cutter.TriangleGrid`: vertices and upward unit normal) against
    ``cutter`` pushed along the fiber ``o + t d`` (unit horizontal ``d``) at tip height
    ``z``; ``t0 = inf, t1 = -inf`` where it never meets the triangle."""
    n = len(ti)
    t0, t1 = np.empty(n), np.empty(n)
    f = np.ascontiguousarray
    _pairs_kernel(rows, f(ti, dtype=np.int64), f(ox, dtype=float), f(oy, dtype=float), f(dx, dtype=float),
                  f(dy, dtype=float), float(z), cutter.code, cutter.radius, cutter.corner, t0, t1)
    return t0, t1

