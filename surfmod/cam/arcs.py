"""Circular (and helical) runs of a polyline tool path, for ``G2``/``G3`` in the posts.

:func:`find_arcs` makes one arc in the XY plane of a run of at least :data:`MIN_POINTS`
locations of one feed when they are samples of the circle through the run's first, middle
and last points (within :data:`TOLERANCE`, each step at most :data:`MAX_STEP_ANGLE`, the
run at most :data:`MAX_SWEEP`, the sagitta over each chord at most :data:`MAX_SAGITTA`),
never above it as a helix and never lower than the points it replaces; a radius beyond
:data:`MAX_RADIUS` is a straight line.  See :doc:`/guide/cam` (section "A job from stock").

>>> import numpy as np
>>> t = np.linspace(0, np.pi / 2, 25)
>>> pts = np.column_stack([5 * np.cos(t), 5 * np.sin(t), -t])   # a quarter helix
>>> [(a.start, a.end, a.ccw, round(a.radius, 9)) for a in find_arcs(pts)]
[(0, 24, True, 5.0)]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Largest distance (mm) of a point of the run from the fitted circle (radially) and above its helix.
TOLERANCE = 1e-4
#: Largest distance (mm) the arc may stand off a chord of the path between two points.
MAX_SAGITTA = 1e-2
#: Largest angle (degrees) between two consecutive points of an arc, and the largest sweep of one arc word.
MAX_STEP_ANGLE = 30.0
MAX_SWEEP = 180.0
#: Fewest points of an arc (four chords), and the largest radius (mm) taken for one.
MIN_POINTS = 5
MAX_RADIUS = 1e4


@dataclass(frozen=True)
class ArcRun:
    """Points ``start..end`` (inclusive indices) of a path lie on the circle round ``centre``
    (XY) of ``radius``, swept counter-clockwise (``G3``) when ``ccw``, else ``G2``."""

    start: int
    end: int
    centre: tuple
    radius: float
    ccw: bool


def _circle(a, b, c):
    """Centre and radius of the circle through three XY points (None when collinear)."""
    ab, ac = b - a, c - a
    d = 2.0 * (ab[0] * ac[1] - ab[1] * ac[0])
    scale = max(float(np.dot(ab, ab)), float(np.dot(ac, ac)), 1e-300)
    if abs(d) <= 1e-12 * scale:
        return None
    ux = (ac[1] * np.dot(ab, ab) - ab[1] * np.dot(ac, ac)) / d
    uy = (ab[0] * np.dot(ac, ac) - ac[0] * np.dot(ab, ab)) / d
    return a + np.array([ux, uy]), float(np.hypot(ux, uy))


def _fits(pts: np.ndarray, tolerance: float, sagitta: float):
    """The :class:`ArcRun` fields (centre, radius, ccw) when ``pts`` are one arc, else None."""
    n = len(pts)
    got = _circle(pts[0, :2], pts[n // 2, :2], pts[-1, :2])
    if got is None:
        return None
    centre, r = got
    if r > MAX_RADIUS or r <= tolerance:
        return None
    rel = pts[:, :2] - centre
    if np.abs(np.hypot(rel[:, 0], rel[:, 1]) - r).max() > tolerance:
        return None
    step = np.diff(np.unwrap(np.arctan2(rel[:, 1], rel[:, 0])))
    if not (np.all(step > 0) or np.all(step < 0)):
        return None
    if np.abs(step).max() > np.radians(MAX_STEP_ANGLE) or abs(step.sum()) > np.radians(MAX_SWEEP) + 1e-12:
        return None
    if r * (1.0 - np.cos(np.abs(step).max() / 2)) > sagitta:
        return None
    # Z linear in the angle, the helix never below a point it replaces
    frac = np.r_[0.0, np.cumsum(step)] / step.sum()
    dz = pts[0, 2] + (pts[-1, 2] - pts[0, 2]) * frac - pts[:, 2]
    if dz.min() < -1e-9 or dz.max() > tolerance:
        return None
    return (float(centre[0]), float(centre[1])), r, bool(step[0] > 0)


def find_arcs(points, kind=None, *, tolerance: float = TOLERANCE, sagitta: float = MAX_SAGITTA) -> list[ArcRun]:
    """The arcs of the path ``points (N, 3)``, in order and disjoint but for shared end
    points; ``kind (N,)`` (how each point is reached) must be one value along an arc
    (its first point excepted).  Greedy: each arc as long as it fits, then the next.

    >>> import numpy as np
    >>> square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0]], float)
    >>> find_arcs(square)   # corners on a circle, steps of 90 degrees: a polygon, not an arc
    []
    """
    pts = np.asarray(points, float)
    n = len(pts)
    kind = np.zeros(n, np.int8) if kind is None else np.asarray(kind)
    if n < MIN_POINTS:
        return []
    # cheap screen: the turning of each triple of points, one way and small, on a finite radius
    seg = np.diff(pts[:, :2], axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    cross = seg[:-1, 0] * seg[1:, 1] - seg[:-1, 1] * seg[1:, 0]
    dot = (seg[:-1] * seg[1:]).sum(axis=1)
    turn = np.arctan2(cross, dot)
    ok = ((length[:-1] > tolerance) & (length[1:] > tolerance) & (np.abs(turn) > 1e-9)
          & (np.abs(turn) <= np.radians(MAX_STEP_ANGLE)) & (kind[1:-1] == kind[2:]))
    # turn[i] is at point i + 1; an arc from i to j needs ok and one sign on turns i .. j - 2
    arcs, i = [], 0
    while i <= n - MIN_POINTS:
        if not ok[i] or kind[i + 1] != kind[i + 2]:
            i += 1
            continue
        sign = np.sign(turn[i])
        # the farthest j the screen allows
        j = i + 1
        while j < n - 1 and ok[j - 1] and np.sign(turn[j - 1]) == sign:
            j += 1
        if j - i + 1 < MIN_POINTS:
            i = j
            continue
        # longest fitting run from i: grow by doubling, then bisect
        lo, hi = i + MIN_POINTS - 1, None
        if _fits(pts[i:lo + 1], tolerance, sagitta) is None:
            i += 1
            continue
        step = MIN_POINTS
        while hi is None:
            cand = min(lo + step, j)
            if cand == lo:
                hi = lo + 1
            elif _fits(pts[i:cand + 1], tolerance, sagitta) is not None:
                lo, step = cand, 2 * step
                if cand == j:
                    hi = j + 1
            else:
                hi = cand
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if _fits(pts[i:mid + 1], tolerance, sagitta) is not None:
                lo = mid
            else:
                hi = mid
        centre, r, ccw = _fits(pts[i:lo + 1], tolerance, sagitta)
        arcs.append(ArcRun(i, lo, centre, r, ccw))
        i = lo
    return arcs
