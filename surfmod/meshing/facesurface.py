"""A face's surface evaluated as OCCT evaluates it, vectorized, for measuring meshes of
real parts: B-spline and Bezier surfaces through the NumPy evaluator, surfaces of
revolution and of linear extrusion from their basis curve (B-spline, Bezier, line,
circle, ellipse) in closed form, and OCCT's ``D1`` per point for anything else.

An extrusion of a B-spline or Bezier curve over a known UV box *is* a B-spline surface
(the curve's net and its copy moved along the direction, degree 1 across, linear in v
as OCCT's ``C(u) + v D``), so it goes through the same compiled kernels as B-spline
faces: projection, partials to order 2.

Parameters are OCCT's: periodic directions wrap into their period (a face trimmed
across the seam of a periodic B-spline lives on both sides of it), other directions
are clamped to the parameter range (pcurves may overshoot by a tolerance).
"""

from __future__ import annotations

import numpy as np

from ..eval import local
from ..nets.bezier import BezierCurve, BezierSurface
from ..nets.bspline import BSplineCurve, BSplineSurface


class _Curve:
    """Position and first derivative ``(N, 2, 3)`` of a basis curve in OCCT's
    parametrization (closed forms for lines and conics, NumPy for splines)."""

    def __init__(self, info: dict):
        self.spline = None
        self.info = info
        self._net = None
        if "bspline" in info:
            d = info["bspline"]
            self.spline = BSplineCurve(d["points"], d["degree"], d["knots"], d["weights"])
            # the compiled surface kernels evaluate the curve as the ruled surface between
            # two copies of it (degree 1 across): C(t) = S(0, t), C'(t) = S_v(0, t)
            h = self.spline._homogeneous
            self._net = local.prepare(np.array([0.0, 0.0, 1.0, 1.0]), 1, self.spline.knots, self.spline.degree,
                                      np.stack([h, h]))
        elif "bezier" in info:
            self.spline = BezierCurve(info["bezier"]["points"], info["bezier"]["weights"])
        self.supported = self.spline is not None or "line" in info or "conic" in info

    def d1(self, t: np.ndarray) -> np.ndarray:
        if self.spline is not None:
            lo, hi = self.spline.domain
            t = np.clip(t, lo, hi)
            if self._net is not None:
                return local.surface_derivatives(self._net, np.zeros(len(t)), t, 1)[:, 0]
            return self.spline._derivatives(t, 1)
        if "line" in self.info:
            o, d = self.info["line"]
            return np.stack([o + t[:, None] * d, np.broadcast_to(d, (len(t), 3))], axis=1)
        c, x, y, a, b = self.info["conic"]
        cos, sin = np.cos(t)[:, None], np.sin(t)[:, None]
        return np.stack([c + a * cos * x + b * sin * y, -a * sin * x + b * cos * y], axis=1)


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
        from ..occ.mesh import surface_info, swept_info

        info = surface_info(surf)
        self.name = info["name"]
        self.periodic = info["periodic"]
        self.period = info["period"]
        self.range = info["range"]
        self.surf = surf
        self._spline = None
        self._swept = None
        if info["bspline"] is not None:
            d = info["bspline"]
            net = np.asarray(d["control_points"], float)
            if np.isfinite(net).all():
                # OCCT's Geom_BSplineSurface has validated its knots, multiplicities and
                # weights; only the poles of a damaged file can be non-finite
                self._spline = BSplineSurface._trusted(net, d["degree"], d["knots"], d["weights"])
            else:  # refused with the argument named
                self._spline = BSplineSurface(net, d["degree"], d["knots"], d["weights"])
        elif info["bezier"] is not None:
            self._spline = BezierSurface(info["bezier"]["control_points"], info["bezier"]["weights"])
        else:
            swept = swept_info(surf)
            curve = None if swept is None else _Curve(swept["curve"])
            if curve is not None and curve.spline is not None and "direction" in swept and bounds is not None:
                self._spline = _extrusion_net(curve.spline.to_bspline(), swept["direction"], bounds[2:])
            elif curve is not None and curve.supported:
                self._swept = swept | {"eval": curve}
        if self._spline is not None:
            self.range = tuple(tuple(float(x) for x in r) for r in self._spline.domain)

    @property
    def spline(self) -> bool:
        """Whether the surface is evaluated as a B-spline or Bezier net (B-spline and
        Bezier surfaces, extrusions of spline curves given their box): :meth:`d2` and,
        for B-splines, :attr:`projector` are available."""
        return self._spline is not None

    @property
    def numpy(self) -> bool:
        """Whether evaluation runs in NumPy (else OCCT per point)."""
        return self._spline is not None or self._swept is not None

    def _map(self, x: np.ndarray, direction: int) -> np.ndarray:
        lo, hi = self.range[direction]
        if self.periodic[direction]:
            return lo + np.mod(x - lo, self.period[direction])
        return np.clip(x, lo, hi)

    def d1(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self._spline is not None:
            return self._spline._derivatives(self._map(u, 0), self._map(v, 1), 1)
        if self._swept is not None:
            return self._swept_d1(self._map(np.asarray(u, float), 0), self._map(np.asarray(v, float), 1))
        from ..occ.mesh import surface_d1

        return surface_d1(self.surf, u, v)

    def d2(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Partials to order 2, ``(N, 3, 3, 3)``, of a surface evaluated as a spline
        (``spline`` is true)."""
        return self._spline._derivatives(self._map(u, 0), self._map(v, 1), 2)

    @property
    def projector(self):
        """``project(points, uv, bounds, threshold) -> distances``, the compiled
        equivalent of :func:`surfmod.meshing.deviation.project_distances` on this
        surface (:mod:`surfmod.eval.projection_kernel`), or ``None`` when the surface is
        not a B-spline net."""
        if not isinstance(self._spline, BSplineSurface):
            return None
        return self._project

    @property
    def parameter_map(self) -> tuple:
        """``(lo, hi, period, periodic)`` per direction as the compiled kernels take them
        (how parameters wrap or clamp)."""
        cached = self.__dict__.get("_parameter_map")
        if cached is None:
            cached = self._parameter_map = (
                np.array([r[0] for r in self.range], float), np.array([r[1] for r in self.range], float),
                np.array([float(t) if k else 0.0 for t, k in zip(self.period, self.periodic)]),
                np.array(self.periodic, bool))
        return cached

    def _project(self, points: np.ndarray, uv: np.ndarray, bounds, threshold: float = 0.0) -> np.ndarray:
        from ..eval import projection_kernel  # numba: compiled on first use, then cached

        net = self._spline._local_net()
        out = np.empty(len(points))
        projection_kernel.project_distances(
            net.knots_u, net.p, net.knots_v, net.q, net.ctrl, net.rational, net.inv_u, net.inv_v, net.bucket_u,
            net.bucket_v, *self.parameter_map, np.array(bounds, float),
            np.ascontiguousarray(points, float), np.ascontiguousarray(uv, float), float(threshold), out,
            float(threshold))
        return out

    def d0(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self._spline is not None:
            return self._spline._derivatives(self._map(u, 0), self._map(v, 1), 0)[:, 0, 0]
        return self.d1(u, v)[:, 0, 0]

    def _swept_d1(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.zeros((len(u), 2, 2, 3))
        sw = self._swept
        if "direction" in sw:  # extrusion: S(u, v) = C(u) + v D
            c = sw["eval"].d1(u)
            d = sw["direction"]
            out[:, 0, 0] = c[:, 0] + v[:, None] * d
            out[:, 1, 0] = c[:, 1]
            out[:, 0, 1] = d
            return out
        # revolution: C(v) turned by the angle u about the axis (Rodrigues)
        o, a = sw["axis"]
        c = sw["eval"].d1(v)
        cos, sin = np.cos(u)[:, None], np.sin(u)[:, None]

        def turn(w):
            along = (w @ a)[:, None] * a
            return (w - along) * cos + np.cross(a, w) * sin + along

        w = c[:, 0] - o
        out[:, 0, 0] = o + turn(w)
        out[:, 1, 0] = np.cross(a, turn(w))
        out[:, 0, 1] = turn(c[:, 1])
        return out


def _extrusion_net(curve: BSplineCurve, direction: np.ndarray, v_box) -> BSplineSurface:
    """``C(u) + v D`` for ``v`` over ``v_box`` widened by its length on each side, as a
    B-spline surface of degree 1 in v: the curve's homogeneous net at both ends of the
    v interval (exact: the v basis functions are the two linear weights of v)."""
    v0, v1 = float(v_box[0]), float(v_box[1])
    margin = max(v1 - v0, 1e-6 * (1.0 + abs(v0) + abs(v1)))
    lo, hi = v0 - margin, v1 + margin
    pts = curve.control_points
    net = np.stack([pts + lo * direction, pts + hi * direction], axis=1)
    weights = None if curve.weights is None else np.stack([curve.weights, curve.weights], axis=1)
    return BSplineSurface._trusted(net, (curve.degree, 1), (curve.knots, np.array([lo, lo, hi, hi])), weights)
