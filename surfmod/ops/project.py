"""Closest-point projection of many points (or a sampled curve) onto a surface or a
trimmed face (the seeding and Newton iteration live in :mod:`surfmod.ops.closest`)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import checks
from ..curve import Curve
from ..errors import SurfmodError
from ..inputs import edge_positions
from .clip import as_face_surface, project_on_face
from ..readback.trimmed import TrimmedFace
from ..surface import Surface, require_surface
from .closest import closest_points
from tqdm import tqdm


class Projection(NamedTuple):
    """Closest points: parameters ``u``, ``v``, the surface ``point`` and the ``distance``.

    >>> import surfmod as sm
    >>> pr = sm.project([(0, 0, 5)], sm.sphere(2.0))
    >>> [round(float(x), 12) for x in (pr.distance[0], pr.point[0][2])]
    [3.0, 2.0]
    """

    u: np.ndarray
    v: np.ndarray
    point: np.ndarray
    distance: np.ndarray


def _as_points(points_or_curve, samples):
    if isinstance(points_or_curve, Curve):
        t0, t1 = points_or_curve.domain
        return points_or_curve.points(np.linspace(t0, t1, samples))
    if hasattr(points_or_curve, "wrapped") and hasattr(points_or_curve, "position_at"):
        # a build123d Edge / Wire: sampled uniformly in its normalized parameter
        return edge_positions(points_or_curve, np.linspace(0.0, 1.0, samples))
    return checks.finite_array(points_or_curve, "points_or_curve", last=3)


#: default cap on the number of points of one ``project`` call (about a minute of work)
MAX_PROJECT_POINTS = 100_000
#: points per block; a progress bar shows from the second block on
_BLOCK = 10_000


def project(points_or_curve, s: Surface, *, samples: int = 65, seeds: int = 8,
            max_points: int = MAX_PROJECT_POINTS, progress: bool | None = None) -> Projection:
    """Closest points on ``s`` to many points at once (or to ``samples`` points of a curve).

    ``points_or_curve``: a point ``(3,)``, points ``(..., 3)``, a surfmod curve or a
    build123d ``Edge``/``Wire`` (sampled at ``samples`` equally spaced parameters).
    Returns ``Projection(u, v, point, distance)`` with the points' leading shape.  The
    closest point may lie on the boundary of the domain (a constrained minimum).  ``s``
    may be a build123d / OCP face or a face read back with :func:`surfmod.from_face`:
    distances are then to the trimmed face, its boundary included.

    More than ``max_points`` points are refused before any work (raise it to allow
    them); work of more than one block of 10,000 points shows a tqdm progress bar
    (``progress=False`` hides it).  A distance that is not finite raises ``SurfmodError``.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    >>> pr = sm.project([(0.25, 0.5, 2.0), (3.0, 0.5, 0.0)], s)
    >>> pr.u, pr.v, pr.distance
    (array([0.25, 1.  ]), array([0.5, 0.5]), array([2., 2.]))
    """
    s = require_surface(as_face_surface(s), "s")  # a face is a trimmed surface: distances are to the face
    samples = checks.count(samples, "samples", minimum=2, maximum=checks.MAX_POINTS)
    seeds = checks.count(seeds, "seeds", minimum=1, maximum=64)
    pts = _as_points(points_or_curve, samples)
    shape = pts.shape[:-1]
    flat = pts.reshape(-1, 3)
    if flat.shape[0] == 0:
        empty = np.empty(shape)
        return Projection(empty, empty.copy(), np.empty(shape + (3,)), empty.copy())
    checks.work(len(flat), max_points, "max_points", f"projecting {len(flat):,} points")
    blocks = range(0, len(flat), _BLOCK)
    if progress or (progress is None and len(blocks) > 1):
        blocks = tqdm(blocks, desc="project", unit="block")
    parts = [closest_points(s, flat[b0 : b0 + _BLOCK], seeds) for b0 in blocks]
    u, v, p, d = (np.concatenate(a) for a in zip(*parts))
    if isinstance(s, TrimmedFace):
        u, v, p, d = project_on_face(s, flat, u, v, p, d)
    if not (np.isfinite(d).all() and np.isfinite(p).all()):
        i = int(np.argmax(~np.isfinite(d) | ~np.isfinite(p).all(axis=1)))
        raise SurfmodError(f"points_or_curve: the closest point to point {i} is not finite (the point is too far away)")
    return Projection(u.reshape(shape), v.reshape(shape), p.reshape(shape + (3,)), d.reshape(shape))
