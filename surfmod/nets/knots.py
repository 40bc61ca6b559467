"""Knot-vector algorithms on homogeneous control arrays: insertion, segmentation,
Bézier extraction.  Control arrays have the control index first; any trailing axes
(other net direction, coordinates) ride along, so one routine serves curves and both
directions of a surface (the net is transposed by the caller).
"""

from __future__ import annotations

import numpy as np


def span_samples(breaks: np.ndarray, per_span: int) -> np.ndarray:
    """``per_span`` equally spaced parameters in each span between consecutive ``breaks``
    (the span's start included), then the last break.

    >>> span_samples(np.array([0.0, 1.0, 3.0]), 2).tolist()
    [0.0, 0.5, 1.0, 2.0, 3.0]
    """
    t = np.linspace(0.0, 1.0, per_span + 1)[:-1]
    return np.concatenate([(breaks[:-1, None] + np.diff(breaks)[:, None] * t).ravel(), breaks[-1:]])


def greville(knots: np.ndarray, degree: int) -> np.ndarray:
    """Greville abscissae: the means of ``degree`` consecutive knots, one per control
    point.  A spline whose control values are a linear function of them is that linear
    function, and they are the collocation sites of degree elevation.  A window of equal
    knots gives that knot exactly (a clamped vector's first and last lie on its ends).

    >>> greville(np.array([0.0, 0, 0, 0.5, 1, 1, 1]), 2).tolist()
    [0.0, 0.25, 0.75, 1.0]
    """
    n = len(knots) - degree - 1
    windows = np.lib.stride_tricks.sliding_window_view(knots[1:-1], degree)[:n]
    return np.clip(windows.mean(axis=1), windows[:, 0], windows[:, -1])


def multiplicity(knots: np.ndarray, t: float) -> int:
    """How many times ``t`` occurs in ``knots`` (exact comparison)."""
    return int(np.count_nonzero(knots == t))


def insert_knot(knots: np.ndarray, degree: int, ctrl: np.ndarray, t: float, times: int):
    """Boehm insertion of ``t`` ``times`` times (Piegl & Tiller A5.1), vectorized over
    the trailing axes of ``ctrl``.  Returns ``(new_knots, new_ctrl)``; the shape of the
    spline is unchanged."""
    p = degree
    n = ctrl.shape[0]
    if times <= 0:
        return knots, ctrl
    k = int(np.clip(np.searchsorted(knots, t, side="right") - 1, p, n - 1))
    s = multiplicity(knots, t)
    r = times
    new_knots = np.concatenate([knots[: k + 1], np.full(r, t), knots[k + 1 :]])
    q = np.empty((n + r,) + ctrl.shape[1:])
    q[: k - p + 1] = ctrl[: k - p + 1]
    q[k - s + r :] = ctrl[k - s :]
    rr = ctrl[k - p : k - s + 1].copy()
    last = k - p
    for j in range(1, r + 1):
        last = k - p + j
        for i in range(p - j - s + 1):
            alpha = (t - knots[last + i]) / (knots[i + k + 1] - knots[last + i])
            rr[i] = alpha * rr[i + 1] + (1.0 - alpha) * rr[i]
        q[last] = rr[0]
        q[k + r - j - s] = rr[p - j - s]
    for i in range(last + 1, k - s):
        q[i] = rr[i - last]
    return new_knots, q


def raise_multiplicity(knots, degree, ctrl, t, target):
    """Insert ``t`` until its multiplicity is at least ``target``."""
    return insert_knot(knots, degree, ctrl, t, target - multiplicity(knots, t))


def segment(knots: np.ndarray, degree: int, ctrl: np.ndarray, a: float, b: float):
    """The exact piece of the spline over ``[a, b]`` as a clamped spline."""
    p = degree
    knots, ctrl = raise_multiplicity(knots, p, ctrl, a, p)
    knots, ctrl = raise_multiplicity(knots, p, ctrl, b, p)
    s = int(np.searchsorted(knots, a, side="right")) - p
    e = int(np.searchsorted(knots, b, side="left"))
    sub_knots = np.concatenate([[a], knots[s : e + p], [b]])
    return sub_knots, ctrl[s - 1 : e].copy()


def smooth_mask(knots: np.ndarray, degree: int, t: np.ndarray, order: int) -> np.ndarray:
    """False where ``t`` is (within a few ulps of) a knot with spans on both sides across
    which the ``order``-th derivative jumps (multiplicity > degree - order).  There the
    derivative is two-valued: surfmod returns the one of the span ``t`` falls in, while
    OCCT's span search (``BSplCLib::LocateParameter``) snaps a parameter that close to the
    knot onto it, so comparisons skip such parameters.  Such knots are the interior ones,
    and the ends of the domain of an unclamped vector (a periodic spline's seam: its spans
    run on past it, so a parameter an ulp below the seam falls in the span before).

    >>> smooth_mask(np.array([0, 0, 0.6000000000000001, 3, 3]), 1, np.array([0.3, 0.6, 0.6000000000000001]), 1)
    array([ True, False, False])
    >>> periodic = np.array([-1.0, 0, 0, 1, 1, 2, 2, 3])  # degree 2, double knots: C0
    >>> smooth_mask(periodic, 2, np.array([-4.4e-16, 0.5, 2.0]), 1)
    array([False,  True, False])
    """
    # strictly inside the whole vector: on a clamped one the ends of the domain repeat
    # degree + 1 times and drop out, on an unclamped one they are knots like the others
    inner = knots[(knots > knots[0]) & (knots < knots[-1])]
    values, mult = np.unique(inner, return_counts=True)
    jumps = values[mult > degree - order]
    if not jumps.size:
        return np.ones(np.shape(t), dtype=bool)
    t = np.asarray(t, dtype=float)
    near = np.abs(t[..., None] - jumps) <= 8 * np.finfo(float).eps * np.maximum(1.0, np.abs(jumps))
    return ~near.any(axis=-1)
