"""A face read back: its surface, the face's own parameter bounds and its boundary.

:func:`from_face` is the one reader of OCCT faces in surfmod.  Its :class:`TrimmedFace`
evaluates over the face's UV bounds exactly as OCCT evaluates the face's surface: periodic
directions wrap, and parameters a tolerance beyond the knot range continue the end span's
polynomial, as ``BSplSLib`` does.  The trim stays available (:meth:`TrimmedFace.face`,
:meth:`TrimmedFace.contains`, :meth:`TrimmedFace.boundary_loops`); the untrimmed surface is
:attr:`TrimmedFace.surface`.  See :doc:`/guide/real_parts`.
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..inputs import build123d_face
from ..mass.moments import face_moments
from ..surface import Surface
from .readers import parameter_space, read_surface


class TrimmedFace(Surface):
    """A face of a B-rep as a surfmod surface (see the module notes).

    ``surface`` is the untrimmed surfmod surface in OCCT's parametrization; attributes it
    has (``knots``, ``degree``, ``control_points``, ``radius``...) are reachable on the
    trimmed face too.  ``reversed`` says the face's orientation is opposite to
    ``Su x Sv``.

    >>> import surfmod as sm, build123d as bd
    >>> f = sm.from_face(bd.Cylinder(1, 2).faces()[0])
    >>> type(f.surface).__name__, round(f.area(), 9) == round(4 * 3.141592653589793, 9)
    ('CylindricalSurface', True)
    """

    def __init__(self, surface: Surface, face_shape, geom, bounds, periods, reversed_: bool):
        self.surface = surface
        self.face_shape = face_shape
        self._geom = geom
        u0, u1, v0, v1 = (float(b) for b in bounds)
        self._domain = ((u0, u1), (v0, v1))
        self.periods = tuple(periods)
        self.reversed = bool(reversed_)

    # attributes of the underlying surface (knots, degree, radius, ...) read through;
    # private names never do, so a half-built object cannot recurse here
    def __getattr__(self, name):
        if name.startswith("_") or name in ("surface", "face_shape", "periods", "reversed"):
            raise AttributeError(name)
        return getattr(self.surface, name)

    @property
    def exact_in_occt(self) -> bool:
        return self.surface.exact_in_occt

    @property
    def occt_construct(self) -> str:
        return self.surface.occt_construct

    @property
    def domain(self):
        return self._domain

    # -- evaluation where the face lives --------------------------------------------------
    def _wrap(self, t: np.ndarray, direction: int) -> np.ndarray:
        period = self.periods[direction]
        if period is None:
            return t
        lo, hi = self.surface.domain[direction]
        outside = (t < lo) | (t > hi)
        if not np.any(outside):
            return t
        t = t.copy()
        t[outside] = lo + np.mod(t[outside] - lo, period)
        return t

    def _derivatives(self, u, v, order):
        return self.surface._derivatives(self._wrap(u, 0), self._wrap(v, 1), order)

    def _grid_derivatives(self, us, vs, order):
        return self.surface._grid_derivatives(self._wrap(us, 0), self._wrap(vs, 1), order)

    def _closest_parameters(self, points):
        # closed forms of the untrimmed surface, over the face's own parameter box
        closed_form = getattr(self.surface, "_closest_in", None)
        return None if closed_form is None else closed_form(points, self._domain)

    def geom(self):
        """The face's own OCCT surface (located), the file's exact geometry."""
        return self._geom

    def face(self):
        """The original face as a build123d ``Face``: its trim (holes, cut edges) kept."""
        return build123d_face(self.face_shape)

    def transformed(self, matrix) -> "TrimmedFace":
        """Surface and face both mapped (OCCT ``BRepBuilderAPI_Transform``/``GTransform``).

        >>> import surfmod as sm, build123d as bd
        >>> f = sm.from_face(bd.Box(1, 1, 1).faces()[0]).translated((0, 0, 5))
        >>> float(f.points(*[sum(r) / 2 for r in f.domain])[2]) >= 5.0
        True
        """
        from ..occ.topo import transformed_face

        return from_face(transformed_face(self.face_shape, matrix))

    # -- the trim -------------------------------------------------------------------------
    def contains(self, u, v, tolerance: float | None = None) -> np.ndarray:
        """True where ``(u, v)`` lies on the face (inside its boundary or on it, within
        ``tolerance`` in model units; default the face's own tolerance).

        >>> import surfmod as sm, build123d as bd
        >>> f = sm.from_face(bd.Face(bd.Wire.make_circle(1.0)))
        >>> f.contains([0.0, 0.9], [0.0, 0.9]).tolist()
        [True, False]
        """
        from ..occ.topo import classify_uv

        uu, vv = np.broadcast_arrays(checks.finite_array(u, "u"), checks.finite_array(v, "v"))
        inside = classify_uv(self.face_shape, uu.ravel(), vv.ravel(), tolerance)
        return inside.reshape(uu.shape)

    def boundary_loops(self, samples: int = 32) -> list:
        """The face's wires as ``(N, 2)`` polylines in ``(u, v)``, outer wire first,
        ``samples`` points per edge (from the exact p-curves)."""
        from ..occ.topo import face_wires_uv

        samples = checks.count(samples, "samples", minimum=2)
        return face_wires_uv(self.face_shape, samples)

    def area(self) -> float:
        """Area of the trimmed face (Gauss quadrature on the NumPy evaluator; Green's
        theorem over the exact p-curves for trimmed faces)."""
        return float(face_moments(self)[0])


def _periods(geom, surface):
    """Per direction the period to wrap by, where OCCT's surface is periodic and the
    surfmod surface's own domain covers one period (B-splines, swept periodic curves)."""
    out = []
    for (lo, hi), periodic, period in zip(surface.domain, *parameter_space(geom)[:2]):
        out.append(float(period) if periodic and abs((hi - lo) - period) <= 1e-9 * max(1.0, period) else None)
    return out


def from_face(face) -> TrimmedFace:
    """A surfmod surface for a build123d ``Face`` or an OCP ``TopoDS_Face`` (e.g. from a
    STEP file): a :class:`TrimmedFace` over the face's UV bounds, equal to OCCT there.

    >>> import surfmod as sm, numpy as np
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> s = sm.from_face(sm.BezierSurface(net).face())
    >>> type(s.surface).__name__, s.domain
    ('BezierSurface', ((0.0, 1.0), (0.0, 1.0)))
    """
    from ..occ.geom import downcast_surface
    from ..occ.topo import face_surface, single_face

    shape = single_face(face)
    geom, bounds, reversed_ = face_surface(shape)
    geom = downcast_surface(geom)
    surface = read_surface(geom, bounds)
    return TrimmedFace(surface, shape, geom, bounds, _periods(geom, surface), reversed_)


def surface_of(value, name: str) -> Surface:
    """``value`` if it is a surfmod surface, else the :func:`from_face` of a build123d or
    OCP face; anything else raises one ``SurfmodError`` naming ``name``.

    >>> surface_of("plane", "a")
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: a: expected a surfmod surface or a face, got str
    """
    if isinstance(value, Surface):
        return value
    if getattr(value, "wrapped", None) is None and not hasattr(value, "ShapeType"):
        raise SurfmodError(f"{name}: expected a surfmod surface or a face, got {type(value).__name__}")
    try:
        return from_face(value)
    except SurfmodError as exc:
        raise SurfmodError(f"{name}: {exc}") from None


def from_faces(shapes: list) -> list:
    """:func:`surfmod.from_face` of every face of a part, in order."""
    return [from_face(shape) for shape in shapes]
