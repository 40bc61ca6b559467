"""Stage two of the mass pipeline (:mod:`surfmod.mass`): where a face's parametrization
breaks into pieces that Gauss–Legendre integrates to round-off.

Knots of splines and of the basis curves of swept surfaces, eighth turns on angular
(trigonometric) directions, one piece on polynomial directions.  Faces are those read
back by :func:`surfmod.from_face`: a ``TrimmedFace`` (which ranks above this package and
calls it for its ``area()``) is recognized by the OCCT face it carries (:func:`is_face`).

>>> import surfmod as sm
>>> direction_breaks(sm.sphere(1.0), 0)
'angular'
"""

from __future__ import annotations

import numpy as np

from ..construct.elementary import PlaneSurface, ConicalSurface, CylindricalSurface, SphericalSurface, ToroidalSurface
from ..construct.conics import Conic
from ..construct.extrusion import TabulatedCylinder
from ..construct.offset_surface import OffsetSurface
from ..construct.revolution import RevolutionSurface
from ..surface import Surface

# Gauss–Legendre converges on cos/sin within a quarter turn; pieces on angular directions
ANGULAR_PIECE = np.pi / 4


def is_face(obj) -> bool:
    """Whether ``obj`` is a face read back (``surfmod.readback.TrimmedFace``: a surface
    over an untrimmed ``surface`` that carries its OCCT ``face_shape``)."""
    return isinstance(getattr(obj, "surface", None), Surface) and "face_shape" in vars(obj)


def _breaks(lo: float, hi: float, knots, periodic_piece: float | None, period: float | None = None) -> np.ndarray:
    """Sorted break points in ``[lo, hi]``: the ends, the knots (repeated every
    ``period`` when the direction wraps) and pieces of at most ``periodic_piece``."""
    pts = [lo, hi]
    if knots is not None and len(knots):
        k = np.unique(np.asarray(knots, dtype=float))
        if period is not None:
            shifts = np.arange(np.floor((lo - k[-1]) / period), np.ceil((hi - k[0]) / period) + 1)
            k = (k[None, :] + period * shifts[:, None]).ravel()
        pts.extend(k[(k > lo) & (k < hi)])
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


def _patch_breaks(surface, lo, hi, direction, period):
    b = direction_breaks(surface, direction)
    if isinstance(b, str):
        return _breaks(lo, hi, None, ANGULAR_PIECE)
    return _breaks(lo, hi, b, None, period)
