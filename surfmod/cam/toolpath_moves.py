"""Zig-zag rasters and the straight G1 moves between cutter locations.

``refine_moves`` inserts locations where a straight move would cut and turns steps at walls
into staircases; ``move_gouge`` measures every move again on other sample points, so the
refinement and the verdict share none.  See :doc:`/guide/cam` (section "From a NURBS surface
to G-code").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError

class NoSafePathError(SurfmodError):
    """No tool path within the gouge tolerance could be made (a ``SurfmodError``)."""


# Interior samples per move while refining, and for the final verdict (offset from those).
REFINE_SAMPLES = 2
CHECK_SAMPLES = 3
REFINE_ROUNDS = 40
# Moves steeper than this (rise over run) become vertical + level moves up front.
STEEP_SLOPE = 2.0


def raster(lo, hi, stepover: float, step: float, direction: str, across=None):
    """Zig-zag cutter locations ``(N, 2)`` over the box ``lo``–``hi`` with passes along
    ``direction`` (``"x"`` or ``"y"``) ``stepover`` apart (or at the cross positions
    ``across``, increasing) and points ``step`` apart, joined by links along the box side;
    the pass index of each location (-1 on links) and the cross positions of the passes.

    >>> xy, index, across = raster((0, 0), (2, 1), 1.0, 1.0, "x")
    >>> xy.tolist(), index.tolist()
    ([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [0.0, 1.0]], [0, 0, 0, 1, 1, 1])
    """
    along_axis, across_axis = (0, 1) if direction == "x" else (1, 0)
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    if across is None:
        n_pass = int(np.ceil((hi[across_axis] - lo[across_axis]) / stepover - 1e-9)) + 1
        across = (np.linspace(lo[across_axis], hi[across_axis], max(n_pass, 2))
                  if hi[across_axis] > lo[across_axis] else np.array([lo[across_axis]]))
    across = np.asarray(across, float)
    n_along = int(np.ceil((hi[along_axis] - lo[along_axis]) / step - 1e-9)) + 1
    along = np.linspace(lo[along_axis], hi[along_axis], max(n_along, 2))
    rows, index = [], []
    for k, c in enumerate(across):
        line = along if k % 2 == 0 else along[::-1]
        pts = np.empty((len(line), 2))
        pts[:, along_axis], pts[:, across_axis] = line, c
        if k:  # link from the previous pass along the box side
            prev = rows[-1][-1]
            m = int(np.ceil(abs(c - prev[across_axis]) / step - 1e-9))
            if m > 1:
                link = np.empty((m - 1, 2))
                link[:, along_axis] = prev[along_axis]
                link[:, across_axis] = prev[across_axis] + (c - prev[across_axis]) * np.arange(1, m) / m
                rows.append(link)
                index.append(np.full(m - 1, -1))
        rows.append(pts)
        index.append(np.full(len(line), k))
    return np.concatenate(rows), np.concatenate(index), across


def _excess(height, points: np.ndarray, moves: np.ndarray, counts: np.ndarray, centred: bool):
    """Drop height minus move height at interior samples of ``moves`` (-inf where the tool
    touches nothing): ``t = (j + 1)/(n + 1)``, or ``(j + ½)/n`` when ``centred``.  Returns
    the per-sample excess, the owning move's position in ``moves``, sample (x, y) and drop."""
    owner = np.repeat(np.arange(len(moves)), counts)
    j = np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts, counts)
    n = counts[owner]
    t = (j + 0.5) / n if centred else (j + 1.0) / (n + 1.0)
    a, b = points[moves[owner], :3], points[moves[owner] + 1, :3]
    p = a + t[:, None] * (b - a)
    drop = height(p[:, :2])
    return np.where(np.isnan(drop), -np.inf, drop - p[:, 2]), owner, p[:, :2], drop


def _worst_per_move(excess: np.ndarray, owner: np.ndarray, n_moves: int):
    """Largest excess of each move and the index of its sample (-inf / -1 without samples)."""
    worst = np.full(n_moves, -np.inf)
    arg = np.full(n_moves, -1)
    if len(owner):
        order = np.lexsort((excess, owner))
        last = np.r_[owner[order][1:] != owner[order][:-1], True]
        arg[owner[order][last]] = order[last]
        worst[owner[order][last]] = excess[order][last]
    return worst, arg


def move_gouge(height, points: np.ndarray, moves: np.ndarray | None = None) -> np.ndarray:
    """Per move ``(N-1,)``: the largest depth (drop-cutter height minus the straight
    move's height) at ``CHECK_SAMPLES`` centred interior samples ``t = (j + ½)/n`` and at
    the end points; ≤ 0 means the move clears.  ``height(xy)`` is the drop-cutter height.
    With ``moves`` (indices ``i``: the move from ``points[i]`` to ``points[i + 1]``) only
    those, one depth each.  A fourth column of ``points``, where given, is the drop height
    under each point already known (-inf: the tool touches nothing), taken instead of
    dropping there again.

    >>> import numpy as np
    >>> bump = lambda xy: np.where(np.abs(xy[:, 0] - 1) < 0.3, 1.0, 0.0)
    >>> move_gouge(bump, np.array([[0.0, 0, 0], [2, 0, 0]])).tolist()
    [1.0]
    >>> move_gouge(bump, np.array([[0.0, 0, 0], [2, 0, 0], [4, 0, 0]]), np.array([1])).tolist()
    [0.0]
    """
    every = moves is None
    moves = np.arange(len(points) - 1) if every else np.asarray(moves, np.int64)
    if not len(moves):
        return np.zeros(0)
    excess, owner, _, _ = _excess(height, points, moves, np.full(len(moves), CHECK_SAMPLES), centred=True)
    worst, _ = _worst_per_move(excess, owner, len(moves))
    at = points if every else points[np.r_[moves, moves + 1]]
    ends = at[:, 3] if at.shape[1] > 3 else height(at[:, :2])
    end_excess = np.where(np.isnan(ends), -np.inf, ends - at[:, 2])
    if every:
        return np.maximum(worst, np.maximum(end_excess[:-1], end_excess[1:]))
    return np.maximum(worst, np.maximum(end_excess[:len(moves)], end_excess[len(moves):]))


def lift_moves(height, points: np.ndarray, depth: np.ndarray, target: float, rounds: int = 4):
    """Raise the end points of every move that cuts deeper than ``target`` until none
    does: ``(points, lift per point, depth per move)``.

    Raising both ends of a straight move by ``d`` raises the whole move by ``d``, so its
    depth drops by ``d``; a move sharing a raised end is raised along part of its length
    and cuts no deeper than before.  Lifting therefore never makes a move cut, it only
    leaves material (at most the lift) where the refinement could not follow the part.

    >>> import numpy as np
    >>> bump = lambda xy: np.where(np.abs(xy[:, 0] - 1) < 0.3, 1.0, 0.0)
    >>> pts = np.array([[0.0, 0, 0], [2, 0, 0], [3, 0, 0]])
    >>> moved, lift, depth = lift_moves(bump, pts, move_gouge(bump, pts), 0.1)
    >>> lift.tolist(), np.round(depth, 12).tolist()   # the bump's move now cuts 0.1 at most
    ([0.9, 0.9, 0.0], [0.1, 0.0])
    """
    points, lift = points.copy(), np.zeros(len(points))
    for _ in range(rounds):
        over = np.nonzero(depth > target)[0]
        if not over.size:
            break
        up = np.zeros(len(points))
        np.maximum.at(up, over, depth[over] - target)
        np.maximum.at(up, over + 1, depth[over] - target)
        points[:, 2] += up
        lift += up
        depth = move_gouge(height, points)
    return points, lift, depth


def staircase_steep(points: np.ndarray, index: np.ndarray, slope: float = STEEP_SLOPE):
    """Replace moves steeper than ``slope`` (wall flanks, where a straight move cuts the
    corner) by a vertical and a level move: rising moves go up first, falling moves
    across first, so the tool never leans into the wall."""
    a, b = points[:-1], points[1:]
    run = np.linalg.norm(b[:, :2] - a[:, :2], axis=1)
    rise = b[:, 2] - a[:, 2]
    steep = (np.abs(rise) > slope * run) & (run > 0)
    at = np.nonzero(steep)[0] + 1
    # (a known drop height in a fourth column goes with its (x, y))
    corner = np.where((rise[steep] > 0)[:, None], np.column_stack([a[steep, :2], b[steep, 2], a[steep, 3:]]),
                      np.column_stack([b[steep, :2], a[steep, 2], b[steep, 3:]]))
    return np.insert(points, at, corner, axis=0), np.insert(index, at, -1)


def refine_moves(height, points: np.ndarray, index: np.ndarray, target: float, min_length: float,
                 floor: float, centred: bool = False):
    """Insert cutter locations until every sampled point of every move lies within
    ``target`` of the drop height, above or below: a move whose samples sit far below its
    chord is as suspect as one that cuts, since a wall's flank (where the drop height
    climbs like a square root, or jumps) may hide between them.  Moves shorter than
    ``min_length`` across that are still off become staircases.  Returns the new points and pass indices.  ``floor``: height
    of locations where the tool touches nothing.  ``centred``: sample where the final
    check does (used to repair moves it rejected)."""
    pending = np.ones(len(points) - 1, bool)  # moves not yet verified
    worst_depth = np.inf
    for _ in range(REFINE_ROUNDS):
        moves = np.nonzero(pending)[0]
        if not moves.size:
            return points, index
        counts = np.full(len(moves), REFINE_SAMPLES)
        excess, owner, xy, drop = _excess(height, points, moves, counts, centred)
        # off the chord either way by more than the target (cuts, or a hidden flank)
        off = np.where(np.isfinite(excess), np.abs(excess), -np.inf)
        worst, arg = _worst_per_move(off, owner, len(moves))
        cut, _ = _worst_per_move(excess, owner, len(moves))
        span = np.linalg.norm(points[moves + 1, :2] - points[moves, :2], axis=1)
        # short moves are split no further unless they cut (steep ones become staircases
        # in staircase_steep, which also covers jumps of the drop height at wall edges)
        bad = ((worst > target) & (span > min_length)) | (cut > target)
        pending[moves[~bad]] = False
        if not bad.any():
            return points, index
        worst_depth = float(cut[bad].max())
        moves, arg, span = moves[bad], arg[bad], span[bad]
        a, b = points[moves], points[moves + 1]
        split = span > min_length
        # split: the worst sample becomes a cutter location at its drop height
        new_pts = [np.column_stack([xy[arg[split]], drop[arg[split]], drop[arg[split]]])[:, :points.shape[1]]]
        at = [moves[split] + 1]
        # staircase: up at a, level above the highest sampled drop, down at b
        sample_top = np.full(len(counts), -np.inf)
        np.maximum.at(sample_top, owner, np.nan_to_num(drop, nan=floor))
        sample_top = sample_top[bad]
        top = np.maximum(np.maximum(a[~split, 2], b[~split, 2]), sample_top[~split] + target / 2)
        for end in (a[~split], b[~split]):
            new_pts.append(np.column_stack([end[:, :2], top, end[:, 3:]]))
            at.append(moves[~split] + 1)
        new_pts = np.concatenate(new_pts)
        at = np.concatenate(at)
        order = np.argsort(at, kind="stable")
        new_pts, at = new_pts[order], at[order]
        same_pass = index[at - 1] == index[at]
        new_index = np.where(same_pass, index[at], -1)
        points = np.insert(points, at, new_pts, axis=0)
        index = np.insert(index, at, new_index)
        # moves touching an inserted point are new and unverified; the rest keep their state
        is_new = np.zeros(len(points), bool)
        is_new[at + np.arange(len(at))] = True
        pending = np.insert(pending, at, True)
        pending |= is_new[1:] | is_new[:-1]
    raise NoSafePathError(
        f"toolpath: no safe path found: moves still cut {worst_depth:.3g} deep after {REFINE_ROUNDS} rounds of "
        f"refinement (allowed {target:.3g})")
