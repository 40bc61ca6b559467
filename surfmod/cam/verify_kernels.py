"""The verification's compiled loops: points of the exact part inside the tool, and the
height-field stock swept by the tool and by its shank and holder (see :mod:`surfmod.cam.verify`).

A point's depth inside the tool is measured in its own meridian half-plane (the nearest
point of a surface of revolution lies there); points are bucketed on an (x, y) grid, each
cell's list from its highest point down, so a probe stops at the first point below its tip.
See :doc:`/guide/cam` (section "The verifier's probes").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def profile(d, radius, corner):
    """Height of the tool's lower surface above the tip at ``d`` from the axis."""
    core = radius - corner
    if d <= core:
        return 0.0
    t = d - core
    return corner - math.sqrt(max(corner * corner - t * t, 0.0))


@njit(cache=True, inline="always")
def inside_depth(d, h, radius, corner):
    """Distance of a point (``d``, ``h``) inside the tool to its boundary; -1 outside."""
    if d >= radius or h <= profile(d, radius, corner):
        return -1.0
    core = radius - corner
    side = radius - d
    t = max(d - core, 0.0)
    floor = math.sqrt(t * t + h * h)
    vx, vz = d - core, h - corner
    if vx >= 0.0 and vz <= 0.0:
        ring = abs(corner - math.sqrt(vx * vx + vz * vz))
    else:
        ring = min(math.sqrt(vx * vx + h * h), math.sqrt((radius - d) ** 2 + vz * vz))
    return min(side, floor, ring)


@njit(cache=True, inline="always")
def _gap(px, py, i, j, x0, y0, cell):
    """Horizontal distance from (px, py) to cell (i, j) (0 inside it)."""
    gx = max(x0 + i * cell - px, px - (x0 + (i + 1) * cell), 0.0)
    gy = max(y0 + j * cell - py, py - (y0 + (j + 1) * cell), 0.0)
    return math.sqrt(gx * gx + gy * gy)


@njit(cache=True, inline="always")
def _cells(px, py, radius, x0, y0, cell, nx, ny):
    """The range of buckets within ``radius`` of (px, py): ``i0, i1, j0, j1`` inclusive."""
    i0 = max(int(math.floor((px - radius - x0) / cell)), 0)
    i1 = min(int(math.floor((px + radius - x0) / cell)), nx - 1)
    j0 = max(int(math.floor((py - radius - y0) / cell)), 0)
    j1 = min(int(math.floor((py + radius - y0) / cell)), ny - 1)
    return i0, i1, j0, j1


@njit(cache=True, inline="always")
def _nodes(px, py, radius, x0, y0, cell, nx, ny):
    """The range of stock nodes (``x0 + i * cell``, ``y0 + j * cell``) within ``radius`` of
    (px, py) in x and in y: ``i0, i1, j0, j1`` inclusive."""
    i0 = max(int(math.ceil((px - radius - x0) / cell)), 0)
    i1 = min(int(math.floor((px + radius - x0) / cell)), nx - 1)
    j0 = max(int(math.ceil((py - radius - y0) / cell)), 0)
    j1 = min(int(math.floor((py + radius - y0) / cell)), ny - 1)
    return i0, i1, j0, j1


@njit(cache=True)
def deepest(starts, points, x0, y0, cell, nx, ny, probes, radius, corner):
    """For each probe (tip point) the deepest bucketed point inside the tool and its index
    (-1 and -1 where none is).  A cell's list is read from its highest point down while a
    point could still lie above the tool's lower surface there (its profile at the cell's
    nearest distance)."""
    n = probes.shape[0]
    depth = np.full(n, -1.0)
    which = np.full(n, -1, np.int64)
    for k in range(n):
        px, py, pz = probes[k, 0], probes[k, 1], probes[k, 2]
        i0, i1, j0, j1 = _cells(px, py, radius, x0, y0, cell, nx, ny)
        best, arg = -1.0, -1
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                near = _gap(px, py, i, j, x0, y0, cell)
                if near >= radius:
                    continue
                floor = profile(near, radius, corner)
                c = i * ny + j
                for m in range(starts[c], starts[c + 1]):
                    h = points[m, 2] - pz
                    if h <= floor:
                        break  # the list runs from its highest point down
                    dx, dy = points[m, 0] - px, points[m, 1] - py
                    dep = inside_depth(math.sqrt(dx * dx + dy * dy), h, radius, corner)
                    if dep > best:
                        best, arg = dep, m
        depth[k] = best
        which[k] = arg
    return depth, which


@njit(cache=True)
def drop_heights(starts, points, x0, y0, cell, nx, ny, xy, radius, corner):
    """Tip heights of the tool dropped onto the bucketed points at each ``xy`` (the highest
    ``z - profile(d)`` of the points within the radius; -inf where there is none).  The
    location's own cell is read first; a cell's list stops where even its nearest
    distance's profile cannot beat the best height found."""
    n = xy.shape[0]
    out = np.full(n, -np.inf)
    for k in range(n):
        px, py = xy[k, 0], xy[k, 1]
        ic = int(math.floor((px - x0) / cell))
        jc = int(math.floor((py - y0) / cell))
        i0, i1, j0, j1 = _cells(px, py, radius, x0, y0, cell, nx, ny)
        best = -np.inf
        for pass_ in range(2):
            for i in range(i0, i1 + 1):
                for j in range(j0, j1 + 1):
                    own = i == ic and j == jc
                    if own != (pass_ == 0):
                        continue
                    near = _gap(px, py, i, j, x0, y0, cell)
                    if near >= radius:
                        continue
                    lift = profile(near, radius, corner)
                    c = i * ny + j
                    for m in range(starts[c], starts[c + 1]):
                        if points[m, 2] - lift <= best:
                            break  # nothing lower in this cell can lift the tool more
                        dx, dy = points[m, 0] - px, points[m, 1] - py
                        d = math.sqrt(dx * dx + dy * dy)
                        if d < radius:
                            z = points[m, 2] - profile(d, radius, corner)
                            if z > best:
                                best = z
        out[k] = best
    return out


@njit(cache=True)
def closing(tips, cell, radius, corner):
    """The lowest the tool's lower surface reaches over each node: the least of
    ``tips[node'] + profile(|node - node'|)`` over the nodes within the radius (the
    part's closing by the tool, on the grid; inf where no tip stands in reach)."""
    nx, ny = tips.shape
    out = np.full((nx, ny), np.inf)
    n = int(radius / cell)
    for di in range(-n, n + 1):
        for dj in range(-n, n + 1):
            d = cell * math.sqrt(di * di + dj * dj)
            if d >= radius:
                continue
            f = profile(d, radius, corner)
            for i in range(max(0, -di), min(nx, nx - di)):
                for j in range(max(0, -dj), min(ny, ny - dj)):
                    v = tips[i + di, j + dj] + f
                    if v < out[i, j]:
                        out[i, j] = v
    return out


@njit(cache=True)
def sweep_stock(top, x0, y0, cell, starts, ends, rapid, radii, corners, step):
    """Run the moves over the stock's height field ``top`` (nx, ny) in order: a feed
    lowers every node to the tool's lower surface, a rapid cuts nothing and is measured.
    Each move is stamped at points at most ``step`` apart in (x, y).  Returns, per move,
    how far the tool's lower surface went below the stock's top (the deepest, -inf where
    it covered no stock) and that node's flat index."""
    m = starts.shape[0]
    none = np.zeros((1, 1, 2))
    out = sweep_body(top, x0, y0, cell, starts, ends, rapid, radii, corners, step, none, np.zeros(m, np.int64),
                     np.zeros(1), np.zeros(1), np.zeros(m, np.bool_), False, 0.0, np.zeros((1, 1)), 0.0)
    return out[0], out[1]


@njit(cache=True)
def _log(log_i, log_v, n, index, value):
    """Append (index, value) to the undo log, doubling it when full."""
    if n == log_i.shape[0]:
        grown_i = np.empty(2 * n, np.int64)
        grown_v = np.empty(2 * n)
        grown_i[:n] = log_i
        grown_v[:n] = log_v
        log_i, log_v = grown_i, grown_v
    log_i[n] = index
    log_v[n] = value
    return log_i, log_v


#: nodes a side of the blocks whose highest stock :func:`sweep_body` keeps
BLOCK = 8


@njit(cache=True)
def _block_max(top, out):
    """The highest node of each ``BLOCK`` x ``BLOCK`` block of ``top`` into ``out``."""
    nx, ny = top.shape
    out[:] = -np.inf
    for i in range(nx):
        for j in range(ny):
            b = out[i // BLOCK, j // BLOCK]
            if top[i, j] > b:
                out[i // BLOCK, j // BLOCK] = top[i, j]


@njit(cache=True)
def sweep_body(top, x0, y0, cell, starts, ends, rapid, radii, corners, step, body, tool_of, slack, limit, skip,
               remove, grow, floor, rise):
    """:func:`sweep_stock` with the tool's body above its flutes (the discs ``body[tool_of[k]]``:
    radius, height of the bottom above the tip; radius 0 pads) measured against the stock
    before each stamp: how far the stock stands above a disc's bottom within the disc's
    radius less the tool's ``slack[tool_of[k]]`` (a rub within it is no collision), over the capsule from
    the stamp before to this one (the disc at every point between), at the lower of the
    two heights.  The end's own column is left out where the tool already stands (a
    move's first stamp) or descends vertically (its flutes cut the column on the way down).
    With a ``floor`` as large as ``top`` (the part's top at each node; else ``(1, 1)``)
    only the stock more than ``rise`` above it counts: a disc beside a wall meets the
    stock left on it, not the part's own column under the nodes; a disc with a third
    value (``body[t, q, 2]``) counts only the nodes whose stock stands no more than that
    above the floor (a skin).

    With ``remove``, a move marked ``skip`` or whose body goes deeper than ``limit[tool]``
    into the stock (a negative limit: comes nearer it than that) cuts nothing (its stamps
    undone) and is reported removed, so later moves meet the stock it left; so is a rapid
    whose end goes deeper than ``slack[tool]`` into it.
    The first feed move after a removed one is reached by a plunge straight down onto its
    start (:func:`surfmod.cam.holder.relink`), through the stock the removed moves left: the
    body is measured along that plunge too (the end's own column aside: the flutes cut it on
    the way down), and the move is removed where the plunge would bury it.  A move's own
    measure does not cover it where the move is not measured at all (a move straight up or
    of no length: on zoo's bracket the relink plunged 159 mm onto such moves, the holder
    68 mm into the stock).  A rapid is measured with the tool grown sideways by ``grow``
    (its profile moved out by it: a node stands for the stock up to a cell round it, and a
    sliver narrower than a cell between the nodes the moves left is stock all the same),
    except straight up, where the tool leaves the column it has just cut.  Returns per
    move: ``into`` and its node (as :func:`sweep_stock`), the body's deepest ``sink`` into
    the stock (-inf where it met none) and its node, and ``removed``."""
    nx, ny = top.shape
    m = starts.shape[0]
    into = np.full(m, -np.inf)
    node = np.full(m, -1, np.int64)
    sink = np.full(m, -np.inf)
    sink_node = np.full(m, -1, np.int64)
    removed = np.zeros(m, np.bool_)
    # the highest stock over blocks of BLOCK x BLOCK nodes: a disc skips every block
    # whose highest node stays below its bottom.  Stock only falls between two moves (a
    # removed move's stamps are undone within it), so maxima taken at the start of a move
    # are never below the stock while it lasts; they are taken again once the stamps have
    # visited as many nodes as the grid holds (at most as much work as the stamps)
    bmax = np.empty(((nx + BLOCK - 1) // BLOCK, (ny + BLOCK - 1) // BLOCK))
    _block_max(top, bmax)
    ceiling = bmax.max()
    visits = 0
    lowest = np.full(body.shape[0], np.inf)
    for t in range(body.shape[0]):
        for q in range(body.shape[1]):
            if body[t, q, 0] > slack[t]:
                lowest[t] = min(lowest[t], body[t, q, 1])
    log_i = np.empty(1024, np.int64)
    log_v = np.empty(1024)
    floored = floor.shape[0] == nx and floor.shape[1] == ny
    gap = False  # a move before was removed: the next feed move is reached by a plunge
    for k in range(m):
        if visits > nx * ny:
            _block_max(top, bmax)
            ceiling = bmax.max()
            visits = 0
        if remove and skip[k]:
            removed[k] = gap = True
            continue
        ax, ay, az = starts[k, 0], starts[k, 1], starts[k, 2]
        bx, by, bz = ends[k, 0], ends[k, 1], ends[k, 2]
        radius, corner = radii[k], corners[k]
        tk = tool_of[k]
        if remove and gap and not rapid[k]:
            buried = _plunge_sink(top, x0, y0, cell, ax, ay, az, radius, body[tk], slack[tk], floor, rise)
            if buried > limit[tk]:
                sink[k] = buried
                removed[k] = True
                continue
        length = math.sqrt((bx - ax) ** 2 + (by - ay) ** 2)
        pieces = max(1, int(math.ceil(length / step)))
        if length == 0.0:
            pieces = 0  # a vertical move: its lowest end is stamped alone
        wide = grow if rapid[k] and not (pieces == 0 and bz >= az) else 0.0
        # the body can meet stock only below the highest node (less a negative limit: a
        # clearance asked), and never on the way up
        measure = min(az, bz) + lowest[tk] < ceiling - min(limit[tk], 0.0) and not (pieces == 0 and bz >= az)
        logged = 0
        px, py, pz = ax, ay, az
        for s in range(pieces + 1):
            t = s / pieces if pieces else (1.0 if bz < az else 0.0)
            cx, cy, cz = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
            if measure:
                own = s == 0 or pieces == 0
                zl = min(cz, pz)
                ux, uy = cx - px, cy - py
                uu = ux * ux + uy * uy
                for q in range(body.shape[1]):
                    reach = body[tk, q, 0] - slack[tk]
                    if reach <= 0.0:
                        continue
                    bottom = zl + body[tk, q, 1]
                    thin = body[tk, q, 2] if body.shape[2] > 2 else np.inf
                    i0 = max(int(math.ceil((min(cx, px) - reach - x0) / cell)), 0)
                    i1 = min(int(math.floor((max(cx, px) + reach - x0) / cell)), nx - 1)
                    j0 = max(int(math.ceil((min(cy, py) - reach - y0) / cell)), 0)
                    j1 = min(int(math.floor((max(cy, py) + reach - y0) / cell)), ny - 1)
                    for bi in range(i0 // BLOCK, i1 // BLOCK + 1):
                        for bj in range(j0 // BLOCK, j1 // BLOCK + 1):
                            if bmax[bi, bj] - bottom <= sink[k]:
                                continue  # no node of the block stands higher
                            for i in range(max(i0, bi * BLOCK), min(i1, bi * BLOCK + BLOCK - 1) + 1):
                                gx = x0 + i * cell
                                for j in range(max(j0, bj * BLOCK), min(j1, bj * BLOCK + BLOCK - 1) + 1):
                                    over = top[i, j] - (max(bottom, floor[i, j] + rise) if floored else bottom)
                                    if over <= sink[k] or (floored and top[i, j] - floor[i, j] > thin):
                                        continue
                                    gy = y0 + j * cell
                                    w = 0.0 if uu == 0.0 else min(max(((gx - px) * ux + (gy - py) * uy) / uu, 0.0),
                                                                  1.0)
                                    if math.sqrt((gx - px - w * ux) ** 2 + (gy - py - w * uy) ** 2) >= reach:
                                        continue
                                    if own and math.sqrt((gx - cx) ** 2 + (gy - cy) ** 2) < radius:
                                        continue
                                    sink[k], sink_node[k] = over, i * ny + j
                if remove and sink[k] > limit[tk]:
                    for e in range(logged - 1, -1, -1):  # undo this move's stamps
                        top[log_i[e] // ny, log_i[e] % ny] = log_v[e]
                    removed[k] = True
                    break
            px, py, pz = cx, cy, cz
            i0, i1, j0, j1 = _nodes(cx, cy, radius + wide, x0, y0, cell, nx, ny)
            visits += max(i1 - i0 + 1, 0) * max(j1 - j0 + 1, 0)
            for i in range(i0, i1 + 1):
                dx = x0 + i * cell - cx
                for j in range(j0, j1 + 1):
                    dy = y0 + j * cell - cy
                    d = math.sqrt(dx * dx + dy * dy)
                    if d >= radius + wide:
                        continue
                    z = cz + profile(max(d - wide, 0.0), radius, corner)
                    over = top[i, j] - z
                    if rapid[k]:
                        if over > into[k]:
                            into[k], node[k] = over, i * ny + j
                    elif over > 0.0:
                        if remove and measure:
                            log_i, log_v = _log(log_i, log_v, logged, i * ny + j, top[i, j])
                            logged += 1
                        top[i, j] = z
        if remove and rapid[k] and into[k] > slack[tk]:
            removed[k] = True  # a rapid into the stock left here: the relink comes down at the feed
        if removed[k]:
            gap = True
        elif not rapid[k]:
            gap = False
    return into, node, sink, sink_node, removed


@njit(cache=True)
def _plunge_sink(top, x0, y0, cell, x, y, z, radius, discs, slack, floor, rise):
    """How far the stock stands above the bottom of the discs (radius, height above the tip)
    wider than the end, less ``slack``, of a tool plunged straight down to the tip height
    ``z`` at ``(x, y)`` (-inf where it meets none); the end's own column is cut on the way.
    ``floor`` and ``rise`` as in :func:`sweep_body`."""
    nx, ny = top.shape
    floored = floor.shape[0] == nx and floor.shape[1] == ny
    worst = -np.inf
    for q in range(discs.shape[0]):
        reach = discs[q, 0] - slack
        if reach <= radius:
            continue
        bottom = z + discs[q, 1]
        thin = discs[q, 2] if discs.shape[1] > 2 else np.inf
        i0, i1, j0, j1 = _nodes(x, y, reach, x0, y0, cell, nx, ny)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                if floored and top[i, j] - floor[i, j] > thin:
                    continue
                if radius <= math.hypot(x0 + i * cell - x, y0 + j * cell - y) < reach:
                    worst = max(worst, top[i, j] - (max(bottom, floor[i, j] + rise) if floored else bottom))
    return worst
