"""A face's surface evaluated as OCCT evaluates it, vectorized, for measuring meshes of real
parts: the surfmod surface :func:`surfmod.readback.read_surface` reads, and OCCT per point
only for a type the reader does not know; an extrusion of a spline curve as the B-spline
it is over its box.

Parameters are OCCT's: periodic directions wrap into their period (a face trimmed across
the seam of a periodic B-spline lives on both sides of it), other directions are clamped to
the parameter range (p-curves may overshoot by a tolerance).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..construct.extrusion import TabulatedCylinder
from ..errors import SurfmodError
from ..nets.bezier import BezierCurve, BezierSurface
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..readback.readers import parameter_space, read_surface


class FaceSurface:
    """``d0(u, v)`` ``(N, 3)`` and ``d1(u, v)`` ``(N, 2, 2, 3)`` of a ``Geom_Surface``.

    >>> import surfmod as sm
    >>> from surfmod.gallery.synthetic import wavy_net
    >>> from surfmod.occ.topo import face_surface
    >>> s = sm.BSplineSurface(wavy_net(5, 4), (3, 2))
    >>> ev = FaceSurface(face_surface(s.face())[0])
    >>> import numpy as np; u = np.array([0.2, 0.7]); v = np.array([0.5, 0.1])
    >>> bool(np.allclose(ev.d0(u, v), s.points(u, v), rtol=0, atol=1e-12)), ev.numpy
    (True, True)
    """

    def __init__(self, surf, bounds=None):
        """``bounds``: the face's UV box ``(u0, u1, v0, v1)``, when known; an extrusion of a
        spline curve is then evaluated as a B-spline surface over that box widened by
        its own size on each side (and clamped there, as the other non-periodic
        directions are clamped to their range)."""
        self.periodic, self.period, self.range = parameter_space(surf)
        self.surf = surf
        box = tuple(bounds) if bounds is not None else self.range[0] + self.range[1]
        try:
            surface = read_surface(surf, box)
        except SurfmodError:  # a type the one reader does not know: OCCT per point
            surface = None
        self._surface = surface
        self._spline = None
        if isinstance(surface, (BSplineSurface, BezierSurface)):
            self._spline = surface
        elif (isinstance(surface, TabulatedCylinder) and isinstance(surface.curve, (BSplineCurve, BezierCurve))
              and bounds is not None):
            self._spline = _extrusion_net(surface, bounds[2:])
        if self._spline is not None:
            self.range = tuple(tuple(float(x) for x in r) for r in self._spline.domain)
        self._evaluator = self._surface if self._spline is None else self._spline

    @property
    def spline(self) -> bool:
        """Whether the surface is evaluated as a B-spline or Bezier net (B-spline and
        Bezier surfaces, extrusions of spline curves given their box): :meth:`d2` and,
        for B-splines, :attr:`projector` are available."""
        return self._spline is not None

    @property
    def numpy(self) -> bool:
        """Whether evaluation runs in NumPy (else OCCT per point)."""
        return self._surface is not None

    def _mapped(self, u, v) -> tuple:
        """``(u, v)`` as OCCT takes them: wrapped into periodic directions, else clamped."""
        out = []
        for direction, x in enumerate((np.asarray(u, float), np.asarray(v, float))):
            lo, hi = self.range[direction]
            out.append(lo + np.mod(x - lo, self.period[direction]) if self.periodic[direction] else np.clip(x, lo, hi))
        return out

    def d1(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self._evaluator is not None:
            return self._evaluator._derivatives(*self._mapped(u, v), 1)
        from ..occ.sample import surface_d2

        return surface_d2(self.surf, np.asarray(u, float), np.asarray(v, float))[:, :2, :2]

    def d2(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Partials to order 2, ``(N, 3, 3, 3)``, of a surface evaluated as a spline
        (``spline`` is true)."""
        return self._spline._derivatives(*self._mapped(u, v), 2)

    @property
    def projector(self):
        """``project(points, uv, bounds, threshold) -> distances``, the compiled
        equivalent of :func:`surfmod.ops.closest.project_distances` on this
        surface (:mod:`surfmod.eval.projection_kernel`), or ``None`` when the surface is
        not a B-spline net."""
        if not isinstance(self._spline, BSplineSurface):
            return None
        return self._project

    @cached_property
    def parameter_map(self) -> tuple:
        """``(lo, hi, period, periodic)`` per direction as the compiled kernels take them
        (how parameters wrap or clamp)."""
        return (np.array([r[0] for r in self.range], float), np.array([r[1] for r in self.range], float),
                np.array([float(t) if k else 0.0 for t, k in zip(self.period, self.periodic)]),
                np.array(self.periodic, bool))

    def _project(self, points: np.ndarray, uv: np.ndarray, bounds, threshold: float = 0.0) -> np.ndarray:
        from ..eval import projection_kernel  # numba: compiled on first use, then cached

        net = self._spline._local_net()
        out = np.empty(len(points))
        projection_kernel.project_distances_compiled(
            net.knots_u, net.p, net.knots_v, net.q, net.ctrl, net.rational, net.inv_u, net.inv_v, net.bucket_u,
            net.bucket_v, *self.parameter_map, np.array(bounds, float),
            np.ascontiguousarray(points, float), np.ascontiguousarray(uv, float), float(threshold), out,
            float(threshold))
        return out

    def d0(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self._evaluator is not None:
            return self._evaluator._derivatives(*self._mapped(u, v), 0)[:, 0, 0]
        return self.d1(u, v)[:, 0, 0]


def _extrusion_net(surface: TabulatedCylinder, v_box) -> BSplineSurface:
    """The extrusion of a spline curve ``C(u) + v D`` for ``v`` over ``v_box`` widened by
    its length on each side, as a B-spline surface of degree 1 in v (exact: the v basis
    functions are the two linear weights of v)."""
    v0, v1 = float(v_box[0]), float(v_box[1])
    margin = max(v1 - v0, 1e-6 * (1.0 + abs(v0) + abs(v1)))
    return TabulatedCylinder._trusted(surface.curve, surface.direction, (v0 - margin, v1 + margin)).to_nurbs()
