"""The time a machine takes for a job's moves (:func:`plan`), beside the plain feed-rate sum
(:func:`feed_time`).

Each move runs a trapezoidal (or triangular) velocity profile under the axis limits of a
:class:`~surfmod.cam.machine_table.Machine` projected on its direction, entering and leaving
at the speed of the blend arc each corner allows; one backward and one forward pass give
those speeds, vectorized.  See :doc:`/guide/cam` (section "Cycle time").

>>> import numpy as np
>>> from surfmod.cam.machine_table import Machine
>>> m = Machine(max_velocity=6000, max_acceleration=100)
>>> p = plan(np.array([[0.0, 0, 0], [1000, 0, 0]]), np.array([6000.0]), m)  # 100 mm/s, 100 mm/s²
>>> float(p.time.sum())  # L/v + v/a
11.0
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import checks
from ..errors import SurfmodError
from .machine_table import MACHINE, Machine
from .roughing import FEED, RAPID, Motion

#: A turn smaller than this (radians) is a straight-through point: the speed is kept.
STRAIGHT = 1e-6
#: Moves shorter than this (mm) are dropped: no controller plans a segment of nothing.
SHORTEST = 1e-9
#: Most segments one plan takes (a dozen float arrays of this length are held at once).
MAX_SEGMENTS = 50_000_000


@dataclass(frozen=True)
class Plan:
    """A velocity profile over the segments that have a length: ``length`` (mm), ``cruise``
    (the highest speed each may run, mm/s), ``speed`` at the ``n + 1`` vertices (mm/s; 0 at
    both ends), ``peak`` (the highest speed reached on each segment) and ``time`` (s)."""

    length: np.ndarray
    cruise: np.ndarray
    speed: np.ndarray
    peak: np.ndarray
    time: np.ndarray


def _limit(direction: np.ndarray, limits: tuple) -> np.ndarray:
    """The largest value along each unit ``direction`` whose axis components stay within
    ``limits``: ``min_a limit_a / |u_a|`` (an axis the direction does not move is free)."""
    lim = np.asarray(limits, float)
    with np.errstate(divide="ignore"):
        return np.min(lim / np.abs(direction), axis=1)


def _forward(cap: np.ndarray, gain: np.ndarray) -> np.ndarray:
    """``w_0 = cap_0``, ``w_{k+1} = min(cap_{k+1}, w_k + gain_k)``, as the running minimum of
    ``cap_j + S_k - S_j`` over ``j <= k`` (``S`` the prefix sums of ``gain``)."""
    s = np.concatenate([[0.0], np.cumsum(gain)])
    return s + np.minimum.accumulate(cap - s)


def plan(points, feeds, machine: Machine = MACHINE, *, max_segments: int = MAX_SEGMENTS) -> Plan:
    """The velocity profile of the polyline ``points (n + 1, 3)`` (mm), segment ``k``
    commanded at ``feeds[k]`` (mm/min), starting and ending at rest; see the module."""
    pts = checks.finite_array(points, "points", ndim=2, last=3)
    rate = checks.finite_array(feeds, "feeds", ndim=1)
    if len(rate) != max(len(pts) - 1, 0):
        raise SurfmodError(f"feeds: expected one per segment ({max(len(pts) - 1, 0)}), got {len(rate)}")
    if np.any(rate <= 0):
        raise SurfmodError("feeds: every feed must be > 0")
    checks.work(len(rate), max_segments, "max_segments", "the velocity profile")
    d = np.diff(pts, axis=0)
    length = np.linalg.norm(d, axis=1)
    keep = length > SHORTEST
    d, length, rate = d[keep], length[keep], rate[keep] / 60.0
    if len(length) == 0:
        return Plan(length, rate, np.zeros(1), rate, np.zeros(0))
    u = d / length[:, None]
    cruise = np.minimum(rate, _limit(u, np.asarray(machine.max_velocity) / 60.0))
    acc = _limit(u, machine.max_acceleration)

    # corners: the blend arc's radius from the tolerance and from the room on the moves
    u1, u2 = u[:-1], u[1:]
    turn = u2 - u1
    sin_h = 0.5 * np.linalg.norm(turn, axis=1)  # sin(φ/2)
    cos_h = 0.5 * np.linalg.norm(u1 + u2, axis=1)  # cos(φ/2)
    bent = sin_h > 0.5 * STRAIGHT
    with np.errstate(divide="ignore", invalid="ignore"):
        one_minus_cos = sin_h**2 / (1.0 + cos_h)  # 1 - cos(φ/2) without cancellation
        radius = np.minimum(machine.blend_tolerance * cos_h / one_minus_cos,
                            0.5 * np.minimum(length[:-1], length[1:]) * cos_h / sin_h)
        normal = turn / (2.0 * sin_h[:, None])
    a_n = _limit(np.where(bent[:, None], normal, 1.0), machine.max_acceleration)
    corner = np.where(bent, np.sqrt(np.where(bent, a_n * radius, 0.0)), np.inf)
    cap = np.concatenate([[0.0], np.minimum(corner, np.minimum(cruise[:-1], cruise[1:])) ** 2, [0.0]])

    gain = 2.0 * acc * length
    back = _forward(cap[::-1], gain[::-1])[::-1]
    w = np.maximum(_forward(back, gain), 0.0)
    v = np.sqrt(w)
    v0, v1, w0, w1 = v[:-1], v[1:], w[:-1], w[1:]
    # the highest speed with both ramps on the segment: vp² - w0 + vp² - w1 = 2 a L
    peak = np.minimum(np.sqrt(0.5 * (w0 + w1) + acc * length), cruise)
    flat = np.maximum(length - (2.0 * peak**2 - w0 - w1) / (2.0 * acc), 0.0)
    time = (2.0 * peak - v0 - v1) / acc + flat / peak
    return Plan(length, cruise, v, peak, time)


def rates(motion: Motion, tool, machine: Machine = MACHINE) -> np.ndarray:
    """The commanded rate of each move of ``motion`` (mm/min): rapids at the machine's
    rapid rate, cuts at the tool's feed, ramps and plunges at its plunge feed."""
    kind = motion.kind[1:]
    return np.where(kind == RAPID, machine.rapid, np.where(kind == FEED, tool.feed, tool.plunge_feed))


def feed_time(motion: Motion, tool, machine: Machine = MACHINE) -> float:
    """Seconds of ``motion`` as the plain feed-rate sum: every move at its commanded rate
    from end to end (no acceleration, no axis limit, no corner)."""
    if len(motion.points) < 2:
        return 0.0
    seg = np.linalg.norm(np.diff(motion.points, axis=0), axis=1)
    return float((seg / rates(motion, tool, machine)).sum() * 60.0)


def cycle_time(motion: Motion, tool, machine: Machine = MACHINE) -> float:
    """Seconds ``machine`` takes for ``motion`` with ``tool``'s feeds (:func:`plan`)."""
    if len(motion.points) < 2:
        return 0.0
    return float(plan(motion.points, rates(motion, tool, machine), machine).time.sum())
