"""Stage two of the mass pipeline (:mod:`surfmod.mass`): where a face's parametrization
breaks into pieces that Gauss–Legendre integrates to round-off (:func:`direction_breaks`,
:func:`rational_pieces`, :func:`spline_breaks`).

A ``TrimmedFace`` (which ranks above this package and calls it for its ``area()``) is
recognized by the OCCT face it carries (:func:`is_face`).
See :doc:`/guide/uses` (section "How a face is integrated").

>>> import surfmod as sm
>>> direction_breaks(sm.sphere(1.0), 0)
'angular'
"""

from __future__ import annotations

import numpy as np

from ..construct.elementary import ConicalSurface, CylindricalSurface, PlaneSurface, SphericalSurface, ToroidalSurface
from ..construct.conics import Conic
from ..construct.extrusion import TabulatedCylinder
from ..construct.offset_surface import OffsetSurface
from ..construct.revolution import RevolutionSurface
from ..eval.basis import knots_inside
from ..surface import Surface

# Gauss–Legendre converges on cos/sin within a quarter turn; pieces on angular directions
ANGULAR_PIECE = np.pi / 4


def is_face(obj) -> bool:
    """Whether ``obj`` is a face read back (``surfmod.readback.TrimmedFace``: a surface
    over an untrimmed ``surface`` that carries its OCCT ``face_shape``)."""
    return isinstance(getattr(obj, "surface", None), Surface) and "face_shape" in vars(obj)


def interval_breaks(lo: float, hi: float, knots, periodic_piece: float | None, period: float | None = None) -> np.ndarray:
    """Sorted break points in ``[lo, hi]``: the ends, the knots (repeated every
    ``period`` when the direction wraps) and pieces of at most ``periodic_piece``."""
    pts = [lo, hi]
    if knots is not None and len(knots):
        pts.extend(knots_inside(knots, lo, hi, period))
    if periodic_piece is not None:
        n = int(np.ceil((hi - lo) / periodic_piece - 1e-9))
        pts.extend(np.linspace(lo, hi, max(n, 1) + 1))
    b = np.unique(np.asarray(pts, dtype=float))
    keep = np.concatenate([[True], np.diff(b) > 1e-12 * max(1.0, hi - lo)])
    return b[keep]


def _curve_breaks(curve):
    """Knots of a spline curve; ``"angular"`` for conics; None for lines."""
    if isinstance(curve, Conic):
        return "angular"
    return getattr(curve, "knots", None)


def direction_breaks(surface, direction: int):
    """What splits a surface's parametrization in one direction: knots (array),
    ``"angular"`` (trigonometric) or None (polynomial, one piece)."""
    if is_face(surface):
        surface = surface.surface
    if isinstance(surface, OffsetSurface):
        return direction_breaks(surface.base, direction)
    knots = getattr(surface, "knots", None)
    if isinstance(knots, tuple) and len(knots) == 2:
        return knots[direction]
    if isinstance(surface, RevolutionSurface):
        return "angular" if direction == 0 else _curve_breaks(surface.profile)
    if isinstance(surface, TabulatedCylinder):
        return _curve_breaks(surface.curve) if direction == 0 else None
    if isinstance(surface, PlaneSurface):
        return None
    if isinstance(surface, (SphericalSurface, ToroidalSurface)):
        return "angular"
    if isinstance(surface, (CylindricalSurface, ConicalSurface)):
        return "angular" if direction == 0 else None
    if hasattr(surface, "degree"):  # Bézier: one polynomial piece
        return None
    return "angular"  # unknown analytic: keep pieces short


#: the most pieces a rational span is split into (a weight ratio of 2^16)
MAX_RATIONAL_PIECES = 16


def _weights_along(surface, direction: int):
    """The weights of the rational spline behind ``direction`` of ``surface``, as lines
    along that direction (rows), or None where it is not rational."""
    if isinstance(surface, OffsetSurface):
        return _weights_along(surface.base, direction)
    if isinstance(surface, TabulatedCylinder):  # the swept curve's weights along u
        w = getattr(surface.curve, "weights", None) if direction == 0 else None
        return None if w is None else np.asarray(w, dtype=float)[None, :]
    if isinstance(surface, RevolutionSurface):  # the profile's along v
        w = getattr(surface.profile, "weights", None) if direction == 1 else None
        return None if w is None else np.asarray(w, dtype=float)[None, :]
    w = getattr(surface, "weights", None)
    return None if w is None else np.moveaxis(np.asarray(w, dtype=float), direction, -1)


def rational_pieces(surface, direction: int) -> int:
    """Pieces per knot span along ``direction`` of a rational spline (a NURBS surface, the
    curve of an extrusion, the profile of a revolution): ``⌈log2 r⌉`` (at least 1, at most
    :data:`MAX_RATIONAL_PIECES`), ``r`` the largest ratio of two weights on one line of
    control points along it (1 where the weights do not vary that way).

    >>> import numpy as np, surfmod as sm
    >>> w = np.array([[1, 1 / 3, 1 / 3, 1]] * 2)
    >>> s = sm.BSplineSurface(np.zeros((2, 4, 3)), degree=(1, 3), weights=w)
    >>> rational_pieces(s, 0), rational_pieces(s, 1)
    (1, 2)
    """
    if is_face(surface):
        surface = surface.surface
    lines = _weights_along(surface, direction)
    if lines is None:
        return 1
    lines = np.abs(lines)
    ratio = float((lines.max(axis=-1) / np.maximum(lines.min(axis=-1), 1e-300)).max())
    return int(min(MAX_RATIONAL_PIECES, max(1, np.ceil(np.log2(ratio) - 1e-9))))


def knot_breaks(surface, lo: float, hi: float, knots, direction: int, period: float | None = None) -> np.ndarray:
    """:func:`interval_breaks` at the ``knots`` of a spline direction of ``surface`` (a face read
    back or a surface), each span then split in :func:`rational_pieces` equal pieces."""
    out = interval_breaks(lo, hi, knots, None, period)
    pieces = rational_pieces(surface, direction)
    if pieces > 1:
        out = np.concatenate([out[:1]] + [np.linspace(a, c, pieces + 1)[1:] for a, c in zip(out[:-1], out[1:])])
    return out


def patch_breaks(surface, lo, hi, direction, period):
    b = direction_breaks(surface, direction)
    if isinstance(b, str):
        return interval_breaks(lo, hi, None, ANGULAR_PIECE)
    return knot_breaks(surface, lo, hi, b, direction, period)


def spline_breaks(records: list) -> None:
    """Set ``"breaks"`` on (non-periodic) B-spline p-curve records from their knots, for
    all records at once: every distinct knot strictly inside the edge's range is a break (a
    spline is no more than ``C^(p-1)`` there), between the range's ends.  Not the adaptor's
    ``GeomAbs_CN`` intervals: OCCT 7.9 reports one interval for some curves with simple
    interior knots (a degree-5 p-curve of koch_Follower_Gripper_Static_Part, knots 0.1,
    0.2, 0.3 inside its range), and Gauss across those knots put that face's area 8e-7 off;
    a break OCCT would merge into a nearby end only adds a short piece."""
    if not records:
        return
    knots = [rec["knots"] for rec in records]
    sizes = np.array([len(k) for k in knots])
    count = len(records)
    owner = np.repeat(np.arange(count), sizes)
    flat = np.concatenate(knots)
    ranges = np.array([rec["range"] for rec in records])
    # each interior knot value once (where it first appears), strictly inside its record's
    # range (the end knots bound no interval: a range reaching past them continues the end
    # spans)
    first = np.ones(len(flat), bool)
    first[1:] = (flat[1:] != flat[:-1]) | (owner[1:] != owner[:-1])
    ends = np.cumsum(sizes)
    lo, hi = flat[ends - sizes], flat[ends - 1]
    keep = first & (flat > np.maximum(ranges[:, 0], lo)[owner]) & (flat < np.minimum(ranges[:, 1], hi)[owner])
    kept, kept_owner = flat[keep], owner[keep]
    inside = np.bincount(kept_owner, minlength=count)
    # per record [first, knots inside..., last], laid end to end (kept knots are grouped
    # by record already), handed out as views
    width = inside + 2
    start = np.cumsum(width) - width
    out = np.empty(int(width.sum()))
    out[start] = ranges[:, 0]
    out[start + width - 1] = ranges[:, 1]
    out[np.arange(len(kept)) - (np.cumsum(inside) - inside)[kept_owner] + start[kept_owner] + 1] = kept
    for rec, lo_, n_in in zip(records, start.tolist(), inside.tolist()):
        rec["breaks"] = out[lo_ : lo_ + n_in + 2]
