"""OCCT's elementary surfaces with their own frames and parametrizations.

Every surface here carries a frame ``(origin, x_dir, y_dir, z_dir)`` (an OCCT ``gp_Ax3``;
indirect frames, e.g. after a mirror, are kept as they are) and is evaluated exactly as
OCCT evaluates it:

===========================  ==============================================================
``PlaneSurface``            ``O + u X + v Y``                          (``Geom_Plane``)
``CylindricalSurface``       ``O + R (cos u X + sin u Y) + v Z``        (``Geom_CylindricalSurface``)
``ConicalSurface``           ``O + (R + v sin a)(cos u X + sin u Y) + v cos a Z``
``SphericalSurface``         ``O + R cos v (cos u X + sin u Y) + R sin v Z``
``ToroidalSurface``          ``O + (R + r cos v)(cos u X + sin u Y) + r sin v Z``
===========================  ==============================================================

Similarity transforms keep the analytic type (the frame moves, radii and the linear
parameter ranges scale by ``|s|``, exactly like ``Geom_Surface::Transform``); any other
affine map goes through the exact rational B-spline form (``to_nurbs``).
"""

from __future__ import annotations

import math

import numpy as np

from .. import checks, transforms
from ..errors import SurfmodError
from ..nets.bspline import BSplineSurface
from ..surface import Surface
from . import elementary_closest as closest
from .conics import Arc
from .curves import Line
from .axes import cos_d, frame_transformed, make_frame, sin_d
from .revolution import revolve_nurbs

TWO_PI = 2.0 * math.pi


def _range(value, name, default):
    return default if value is None else checks.interval(value, name)


# -- base ----------------------------------------------------------------------------------------
class ElementarySurface(Surface):
    """Common frame handling of the OCCT elementary surfaces (not built directly)."""

    _linear_u = False  # u is a length (scales under similarity)
    _linear_v = False
    #: the OCCT kind (``occ.analytic.elementary``), the parameters (in the order of
    #: ``_trusted``; ``_occt_sizes`` where OCCT takes another) and those of them that are
    #: lengths (they scale under a similarity)
    _kind = ""
    _sizes: tuple = ()
    _occt_sizes: tuple = ()
    _lengths: tuple = ()

    def _init_frame(self, frame, u_range, v_range):
        self.origin, self.x_dir, self.y_dir, self.z_dir = (checks.frozen(a) for a in frame)
        self._domain = ((float(u_range[0]), float(u_range[1])), (float(v_range[0]), float(v_range[1])))

    @classmethod
    def _trusted(cls, frame, params, u_range, v_range):
        obj = cls._construct_fast()
        obj._init_frame(frame, u_range, v_range)
        obj._set_params(*params)
        return obj

    def _set_params(self, *values):
        for name, value in zip(self._sizes, values):
            setattr(self, name, float(value))

    def _scaled_params(self, s):
        return tuple(getattr(self, n) * s if n in self._lengths else getattr(self, n) for n in self._sizes)

    @property
    def frame(self):
        """``(origin, x_dir, y_dir, z_dir)``."""
        return self.origin, self.x_dir, self.y_dir, self.z_dir

    @property
    def domain(self):
        return self._domain

    @property
    def _spin_axis(self) -> np.ndarray:
        """``X ^ Y``: the axis about which increasing ``u`` turns (``-Z`` if indirect)."""
        return np.cross(self.x_dir, self.y_dir)

    def _local(self, p) -> np.ndarray:
        d = np.asarray(p, dtype=float) - self.origin
        return np.stack([d @ self.x_dir, d @ self.y_dir, d @ self.z_dir], axis=-1)

    def _coefficients(self, u, v, order):
        """``(fx, fy, fz)`` arrays ``(..., K, K)``: partials of the X, Y, Z coordinates,
        for ``u`` and ``v`` broadcast against each other."""
        raise NotImplementedError

    def _derivatives(self, u, v, order):
        fx, fy, fz = self._coefficients(u, v, order)
        out = fx[..., None] * self.x_dir + fy[..., None] * self.y_dir + fz[..., None] * self.z_dir
        out[..., 0, 0, :] += self.origin
        return out

    def _grid_derivatives(self, us, vs, order):
        # separable: the trigonometry runs on the nu + nv parameters, not on nu x nv points
        return self._derivatives(us[:, None], vs[None, :], order)

    def _closest_parameters(self, points):
        return self._closest_in(points, self._domain)

    def _closest_in(self, points, box):
        """``(u, v)`` of the closest points of the parameter box ``box`` to ``(N, 3)``
        points, in closed form (:mod:`surfmod.construct.elementary_closest`)."""
        return self._closest_local(self._local(points), box)

    def _closest_local(self, local, box):
        raise NotImplementedError

    def geom(self):
        from ..occ.analytic import elementary

        sizes = [getattr(self, n) for n in self._occt_sizes or self._sizes]
        return self._twin(lambda: elementary(self._kind, self.frame, *sizes))

    def transformed(self, matrix):
        """Similarity: same analytic type with a moved frame; otherwise the exact NURBS form
        with mapped control points."""
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            return self.to_nurbs().transformed(m)
        frame, s = frame_transformed(self.frame, m)
        (u0, u1), (v0, v1) = self._domain
        ur = (u0 * s, u1 * s) if self._linear_u else (u0, u1)
        vr = (v0 * s, v1 * s) if self._linear_v else (v0, v1)
        return type(self)._trusted(frame, self._scaled_params(s), ur, vr)


def _zeros(shape, order):
    k = order + 1
    return np.zeros((*shape, k, k)), np.zeros((*shape, k, k)), np.zeros((*shape, k, k))


class PlaneSurface(ElementarySurface):
    """OCCT's ``Geom_Plane``: ``S(u, v) = O + u X + v Y`` over ``u_range x v_range``.

    >>> import surfmod as sm
    >>> p = sm.PlaneSurface((0, 0, 1), normal=(0, 0, 1), u_range=(0, 2), v_range=(0, 1))
    >>> p.points(1.0, 0.5)
    array([1. , 0.5, 1. ])
    """

    occt_construct = "Geom_Plane"
    _kind = "plane"
    _linear_u = _linear_v = True

    @property
    def normal(self) -> np.ndarray:
        """The unit normal ``Z`` of the carrier plane (beside ``origin``, like ``ThreePointPlane``)."""
        return self.z_dir

    def __init__(self, origin=(0, 0, 0), normal=(0, 0, 1), x_dir=None, *, u_range=(0.0, 1.0), v_range=(0.0, 1.0)):
        frame = make_frame(origin, normal, x_dir, origin_name="origin", axis_name="normal")
        self._init_frame(frame, _range(u_range, "u_range", None), _range(v_range, "v_range", None))
        self._set_params()

    def _coefficients(self, u, v, order):
        fx, fy, fz = _zeros(np.broadcast_shapes(np.shape(u), np.shape(v)), order)
        fx[..., 0, 0], fy[..., 0, 0] = u, v
        if order >= 1:
            fx[..., 1, 0] = 1.0
            fy[..., 0, 1] = 1.0
        return fx, fy, fz

    def _closest_local(self, local, box):
        return closest.plane(local, box)

    def implicit(self, xyz) -> np.ndarray:
        """Signed distance ``(x - O) . Z``."""
        return self._local(xyz)[..., 2]

    def to_nurbs(self):
        """The same plane as a degree-1 B-spline with the same parametrization."""
        (u0, u1), (v0, v1) = self._domain
        net = np.array([[self.points(u0, v0), self.points(u0, v1)], [self.points(u1, v0), self.points(u1, v1)]])
        return BSplineSurface._trusted(net, (1, 1), (np.array([u0, u0, u1, u1]), np.array([v0, v0, v1, v1])))


class CylindricalSurface(ElementarySurface):
    """OCCT's ``Geom_CylindricalSurface``: ``O + R (cos u X + sin u Y) + v Z``.

    >>> import surfmod as sm
    >>> c = sm.CylindricalSurface(2.0, (0, 0, 0), (0, 0, 1), v_range=(0, 5))
    >>> c.points(0.0, 1.0)
    array([2., 0., 1.])
    """

    occt_construct = "Geom_CylindricalSurface"
    _kind, _sizes, _lengths = "cylinder", ("radius",), ("radius",)
    _linear_v = True

    def __init__(self, radius, origin=(0, 0, 0), axis=(0, 0, 1), x_dir=None, *, u_range=None, v_range=(0.0, 1.0)):
        r = checks.positive(radius, "radius")
        frame = make_frame(origin, axis, x_dir, origin_name="origin")
        self._init_frame(frame, _range(u_range, "u_range", (0.0, TWO_PI)), _range(v_range, "v_range", None))
        self._set_params(r)

    def _coefficients(self, u, v, order):
        fx, fy, fz = _zeros(np.broadcast_shapes(np.shape(u), np.shape(v)), order)
        for k in range(order + 1):
            fx[..., k, 0] = self.radius * cos_d(u, k)
            fy[..., k, 0] = self.radius * sin_d(u, k)
        fz[..., 0, 0] = v
        if order >= 1:
            fz[..., 0, 1] = 1.0
        return fx, fy, fz

    def _closest_local(self, local, box):
        return closest.cylinder(local, box)

    def implicit(self, xyz) -> np.ndarray:
        """``x^2 + y^2 - R^2`` in the frame."""
        p = self._local(xyz)
        return p[..., 0] ** 2 + p[..., 1] ** 2 - self.radius**2

    def to_nurbs(self):
        """Exact rational B-spline (a revolved line)."""
        (u0, u1), (v0, v1) = self._domain
        line = Line.through(self.origin + self.radius * self.x_dir, self.z_dir, (v0, v1))
        return revolve_nurbs(line.to_bspline(), self.origin, self._spin_axis, (u0, u1))


class ConicalSurface(ElementarySurface):
    """OCCT's ``Geom_ConicalSurface``: ``O + (R + v sin a)(cos u X + sin u Y) + v cos a Z``
    (``R`` = reference radius at ``v = 0``, ``a`` = semi-angle in radians, ``v`` measured
    along the generatrix).

    >>> import math, surfmod as sm
    >>> c = sm.ConicalSurface(math.radians(45), 1.0, v_range=(0, 1))
    >>> bool(abs(c.implicit(c.points(0.3, 0.7))) < 1e-12)
    True
    """

    occt_construct = "Geom_ConicalSurface"
    _kind, _sizes, _lengths = "cone", ("radius", "semi_angle"), ("radius",)
    _occt_sizes = ("semi_angle", "radius")
    _linear_v = True

    def __init__(self, semi_angle, ref_radius=0.0, origin=(0, 0, 0), axis=(0, 0, 1), x_dir=None, *,
                 u_range=None, v_range=(0.0, 1.0)):
        a = float(checks.finite_array(semi_angle, "semi_angle"))
        if not 1e-12 < abs(a) < math.pi / 2 - 1e-12:
            raise SurfmodError(f"semi_angle: must lie in (-pi/2, pi/2) and not be 0, got {a:g}")
        r = float(checks.finite_array(ref_radius, "ref_radius"))
        if r < 0:
            raise SurfmodError(f"ref_radius: must be >= 0, got {r:g}")
        frame = make_frame(origin, axis, x_dir, origin_name="origin")
        self._init_frame(frame, _range(u_range, "u_range", (0.0, TWO_PI)), _range(v_range, "v_range", None))
        self._set_params(r, a)

    @property
    def apex(self) -> np.ndarray:
        return self.origin - self.radius / math.tan(self.semi_angle) * self.z_dir

    def _coefficients(self, u, v, order):
        fx, fy, fz = _zeros(np.broadcast_shapes(np.shape(u), np.shape(v)), order)
        sa, ca = math.sin(self.semi_angle), math.cos(self.semi_angle)
        rho = [self.radius + v * sa, sa]
        for k in range(order + 1):
            for l in range(min(order, 1) + 1):
                fx[..., k, l] = cos_d(u, k) * rho[l]
                fy[..., k, l] = sin_d(u, k) * rho[l]
        fz[..., 0, 0] = v * ca
        if order >= 1:
            fz[..., 0, 1] = ca
        return fx, fy, fz

    def _closest_local(self, local, box):
        return closest.cone(local, box, self.radius, self.semi_angle)

    def implicit(self, xyz) -> np.ndarray:
        """``x^2 + y^2 - (R + z tan a)^2`` in the frame."""
        p = self._local(xyz)
        return p[..., 0] ** 2 + p[..., 1] ** 2 - (self.radius + p[..., 2] * math.tan(self.semi_angle)) ** 2

    def to_nurbs(self):
        """Exact rational B-spline (a revolved line)."""
        (u0, u1), (v0, v1) = self._domain
        sa, ca = math.sin(self.semi_angle), math.cos(self.semi_angle)
        line = Line.through(self.origin + self.radius * self.x_dir, sa * self.x_dir + ca * self.z_dir, (v0, v1))
        return revolve_nurbs(line.to_bspline(), self.origin, self._spin_axis, (u0, u1))


class SphericalSurface(ElementarySurface):
    """OCCT's ``Geom_SphericalSurface``: ``O + R cos v (cos u X + sin u Y) + R sin v Z``,
    ``u`` in ``[0, 2 pi]`` (longitude), ``v`` in ``[-pi/2, pi/2]`` (latitude).

    >>> import surfmod as sm
    >>> s = sm.SphericalSurface(2.0)
    >>> s.points(0.0, 0.0), s.domain[1]
    (array([2., 0., 0.]), (-1.5707963267948966, 1.5707963267948966))
    """

    occt_construct = "Geom_SphericalSurface"
    _kind, _sizes, _lengths = "sphere", ("radius",), ("radius",)

    def __init__(self, radius, center=(0, 0, 0), axis=(0, 0, 1), x_dir=None, *, u_range=None, v_range=None):
        r = checks.positive(radius, "radius")
        frame = make_frame(center, axis, x_dir)
        vr = _range(v_range, "v_range", (-math.pi / 2, math.pi / 2))
        if vr[0] < -math.pi / 2 - 1e-12 or vr[1] > math.pi / 2 + 1e-12:
            raise SurfmodError(f"v_range: latitude must stay within [-pi/2, pi/2], got {vr}")
        self._init_frame(frame, _range(u_range, "u_range", (0.0, TWO_PI)), vr)
        self._set_params(r)

    @property
    def center(self) -> np.ndarray:
        return self.origin

    def _coefficients(self, u, v, order):
        fx, fy, fz = _zeros(np.broadcast_shapes(np.shape(u), np.shape(v)), order)
        r = self.radius
        for k in range(order + 1):
            cu, su = cos_d(u, k), sin_d(u, k)
            for l in range(order + 1):
                cv = cos_d(v, l)
                fx[..., k, l] = r * cu * cv
                fy[..., k, l] = r * su * cv
        for l in range(order + 1):
            fz[..., 0, l] = r * sin_d(v, l)
        return fx, fy, fz

    def _closest_local(self, local, box):
        return closest.sphere(local, box)

    def implicit(self, xyz) -> np.ndarray:
        """``|x - C|^2 - R^2``."""
        p = self._local(xyz)
        return np.sum(p * p, axis=-1) - self.radius**2

    def to_nurbs(self):
        """Exact rational B-spline (degree 2 x 2): a revolved circular arc."""
        (u0, u1), (v0, v1) = self._domain
        arc = Arc._from_radians(self.origin, np.cross(self.x_dir, self.z_dir), self.x_dir, self.radius, self.radius, (v0, v1))
        return revolve_nurbs(arc.to_bspline(), self.origin, self._spin_axis, (u0, u1))


class ToroidalSurface(ElementarySurface):
    """OCCT's ``Geom_ToroidalSurface``: ``O + (R + r cos v)(cos u X + sin u Y) + r sin v Z``.

    >>> import surfmod as sm
    >>> t = sm.ToroidalSurface(3.0, 1.0)
    >>> t.points(0.0, 0.0)
    array([4., 0., 0.])
    """

    occt_construct = "Geom_ToroidalSurface"
    _kind, _sizes, _lengths = "torus", ("major", "minor"), ("major", "minor")

    def __init__(self, major, minor, center=(0, 0, 0), axis=(0, 0, 1), x_dir=None, *, u_range=None, v_range=None):
        big = checks.positive(major, "major")
        small = checks.positive(minor, "minor")
        if small >= big:
            raise SurfmodError(f"minor: must be smaller than major ({big:g}) for a ring torus, got {small:g}")
        frame = make_frame(center, axis, x_dir)
        self._init_frame(frame, _range(u_range, "u_range", (0.0, TWO_PI)), _range(v_range, "v_range", (0.0, TWO_PI)))
        self._set_params(big, small)

    @property
    def center(self) -> np.ndarray:
        return self.origin

    def _coefficients(self, u, v, order):
        fx, fy, fz = _zeros(np.broadcast_shapes(np.shape(u), np.shape(v)), order)
        rho = [self.major + self.minor * np.cos(v)] + [self.minor * cos_d(v, l) for l in range(1, order + 1)]
        for k in range(order + 1):
            cu, su = cos_d(u, k), sin_d(u, k)
            for l in range(order + 1):
                fx[..., k, l] = cu * rho[l]
                fy[..., k, l] = su * rho[l]
        for l in range(order + 1):
            fz[..., 0, l] = self.minor * sin_d(v, l)
        return fx, fy, fz

    def _closest_local(self, local, box):
        return closest.torus(local, box, self.major)

    def implicit(self, xyz) -> np.ndarray:
        """``(|p|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + y^2)`` in the frame."""
        p = self._local(xyz)
        big, small = self.major, self.minor
        return (np.sum(p * p, axis=-1) + big**2 - small**2) ** 2 - 4 * big**2 * (p[..., 0] ** 2 + p[..., 1] ** 2)

    def to_nurbs(self):
        """Exact rational B-spline (degree 2 x 2): a revolved circle."""
        (u0, u1), (v0, v1) = self._domain
        center = self.origin + self.major * self.x_dir
        arc = Arc._from_radians(center, np.cross(self.x_dir, self.z_dir), self.x_dir, self.minor, self.minor, (v0, v1))
        return revolve_nurbs(arc.to_bspline(), self.origin, self._spin_axis, (u0, u1))

