"""Per-face evaluators on the NumPy side, for quadrature and drop-cutting.

Every face of a shape becomes a :class:`Patch`: its parameter box, its outward sign, the
break points of its parametrization (knots of splines and of the basis curves of swept
surfaces; quarter turns on angular directions) and an ``evaluate(u, v, order)`` returning
``(N, order+1, order+1, 3)`` partials.  Faces are read only through
:func:`surfmod.from_face` (:mod:`surfmod.readback`), so every surface type the reader
knows is evaluated by the NumPy evaluator, wherever the face lives.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..construct.elementary import PlaneSurface, ConicalSurface, CylindricalSurface, SphericalSurface, ToroidalSurface
from ..construct.conics import Conic
from ..construct.extrusion import TabulatedCylinder
from ..construct.offset_surface import OffsetSurface
from ..construct.revolution import RevolutionSurface
from ..readback import TrimmedFace, from_face

# Gauss–Legendre converges on cos/sin within a quarter turn; pieces on angular directions
ANGULAR_PIECE = np.pi / 4


@dataclass(frozen=True)
class Patch:
    index: int
    kind: str
    bounds: tuple
    sign: float
    natural: bool
    breaks_u: np.ndarray
    breaks_v: np.ndarray
    evaluator: str
    evaluate: object = field(repr=False)
    face: object = field(repr=False, default=None)


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
    if isinstance(surface, TrimmedFace):
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


def face_patch(face: TrimmedFace, index: int = 0) -> Patch:
    """The :class:`Patch` of one face read back with :func:`surfmod.from_face`."""
    from ..occ.uses import is_rectangle

    u0, u1, v0, v1 = (b for r in face.domain for b in r)
    bu = _patch_breaks(face, u0, u1, 0, face.periods[0])
    bv = _patch_breaks(face, v0, v1, 1, face.periods[1])
    return Patch(index, face.geom().DynamicType().Name(), (u0, u1, v0, v1), -1.0 if face.reversed else 1.0,
                 is_rectangle(face.face_shape, (u0, u1, v0, v1)), bu, bv, "numpy", face._derivatives, face.face_shape)


def surface_patch(surf, index: int = 0) -> Patch:
    """A :class:`Patch` for a surfmod surface over its whole domain (NumPy evaluator)."""
    (u0, u1), (v0, v1) = surf.domain
    breaks = []
    for direction, (lo, hi) in enumerate(surf.domain):
        b = direction_breaks(surf, direction)
        # analytic directions without knots: eight pieces keep Gauss converged
        breaks.append(_breaks(lo, hi, None, (hi - lo) / 8) if isinstance(b, str) or b is None else _breaks(lo, hi, b, None))
    return Patch(index, type(surf).__name__, (u0, u1, v0, v1), 1.0, True, breaks[0], breaks[1],
                 "numpy", surf._derivatives, None)


def patches(shape) -> list[Patch]:
    """Patches for every face of an OCCT or build123d shape."""
    from ..occ.topo import faces_of

    return [face_patch(from_face(f), i) for i, f in enumerate(faces_of(shape))]
