"""Surface of revolution: a planar profile rotated about an axis in its plane.

``S(u, v) = O + R_a(u) (C(v) - O)`` with ``R_a(u)`` the right-handed rotation by ``u``
radians about the unit axis ``a`` through ``O`` and ``C`` the profile in its own
parametrization: exactly ``Geom_SurfaceOfRevolution(C, gp_Ax1(O, a))`` (u = angle,
v = profile parameter).  ``to_nurbs()`` gives the exact rational B-spline form (each
profile control point swept along a rational quadratic arc).
"""

from __future__ import annotations

import math

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..surface import Surface
from .axes import cos_d, sin_d
from .conics import arc_segments
from .from_edge import as_curve


def revolve_nurbs(profile: BSplineCurve, origin, axis, u_range) -> BSplineSurface:
    """Exact NURBS of the B-spline ``profile`` revolved about ``(origin, axis)`` over
    ``u_range`` (radians): u is degree 2 rational (arcs of at most 90 degrees, knots on
    ``u_range``), v is the profile's own B-spline."""
    theta, scale, wu, ku = arc_segments(*(float(t) for t in u_range))
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    o = np.asarray(origin, dtype=float)
    p = profile.control_points
    foot = o + ((p - o) @ a)[:, None] * a  # (m, 3)
    xv = p - foot
    size = max(float(np.abs(p - o).max()), 1e-300)
    xv[np.linalg.norm(xv, axis=1) <= 1e-14 * size] = 0.0  # points on the axis: exact poles
    yv = np.cross(a, xv)
    c = (np.cos(theta) * scale)[:, None, None]
    s = (np.sin(theta) * scale)[:, None, None]
    net = foot[None] + c * xv[None] + s * yv[None]  # (2nseg+1, m, 3)
    wv = np.ones(len(p)) if profile.weights is None else profile.weights
    weights = wu[:, None] * wv[None, :]
    return BSplineSurface._trusted(net, (2, profile.degree), (ku, profile.knots), weights)


def axis_plane_check(profile: Curve, origin, axis, name="profile", samples: int = 257):
    """Check that ``profile`` is planar, lies in a plane containing the axis and does not
    cross the axis (touching it is allowed).  Raises ``SurfmodError`` naming ``name``."""
    o, a = np.asarray(origin, float), np.asarray(axis, float)
    ctrl = profile.to_bspline().control_points
    t0, t1 = profile.domain
    pts = profile.points(np.linspace(t0, t1, samples))
    allp = np.concatenate([ctrl, pts])
    rel = allp - o
    perp = rel - (rel @ a)[:, None] * a
    size = max(float(np.abs(rel).max()), 1e-300)
    dist = np.linalg.norm(perp, axis=1)
    if dist.max() <= 1e-12 * size:
        raise SurfmodError(f"{name}: lies on the axis of revolution, the surface would be degenerate")
    ref = perp[np.argmax(dist)] / dist.max()
    off_plane = np.abs(perp @ np.cross(a, ref))
    if off_plane.max() > 1e-9 * size:
        raise SurfmodError(
            f"{name}: must be planar and lie in a plane containing the axis "
            f"(max distance from that plane {off_plane.max():.3g})"
        )
    side = perp[len(ctrl):] @ ref
    tol = 1e-9 * size
    if side.min() < -tol and side.max() > tol:
        raise SurfmodError(f"{name}: crosses the axis of revolution (the surface would self-intersect)")


class RevolutionSurface(Surface):
    """``Geom_SurfaceOfRevolution``: u = rotation angle (radians) over ``u_range``,
    v = the profile's own parameter.  Build with :func:`revolution`.

    >>> import surfmod as sm, numpy as np
    >>> cone = sm.revolution(sm.Line((1, 0, 0), (0, 0, 1)), (0, 0, 0), (0, 0, 1))
    >>> v_mid = cone.domain[1][1] / 2   # the line's parameter is its arc length
    >>> [round(float(x), 12) + 0.0 for x in cone.points(np.pi / 2, v_mid)]   # a quarter turn
    [0.0, 0.5, 0.5]
    """

    occt_construct = "Geom_SurfaceOfRevolution"

    @classmethod
    def _trusted(cls, profile: Curve, origin, axis, u_range):
        obj = cls._construct_fast()
        obj.profile = profile
        obj.axis_origin = checks.frozen(origin)
        obj.axis_direction = checks.frozen(np.asarray(axis, float) / np.linalg.norm(axis))
        obj.u_range = (float(u_range[0]), float(u_range[1]))
        return obj

    @property
    def domain(self):
        return self.u_range, tuple(float(t) for t in self.profile.domain)

    def _derivatives(self, u, v, order):
        return self._rotated(self.profile._derivatives(v, order), u[:, None, None], (u.size,), order)

    def _grid_derivatives(self, us, vs, order):
        """Tensor grid: the profile is evaluated once per v, the rotation once per u."""
        return self._rotated(self.profile._derivatives(vs, order), us[:, None, None, None], (us.size, vs.size), order)

    def _rotated(self, c, u, shape, order):
        """Partials ``shape + (K, K, 3)`` of the profile's partials ``c`` (``(.., K, 3)``)
        turned by the angles ``u`` (broadcasting against ``c``)."""
        a, o = self.axis_direction, self.axis_origin
        c[..., 0, :] -= o
        along = np.einsum("...kd,d->...k", c, a)[..., None] * a  # axial part
        radial = c - along
        cross = np.cross(a, radial)
        out = np.empty((*shape, order + 1, order + 1, 3))
        for k in range(order + 1):
            out[..., k, :, :] = cos_d(u, k) * radial + sin_d(u, k) * cross
        out[..., 0, :, :] += along
        out[..., 0, 0, :] += o
        return out

    def geom(self):
        from ..occ.analytic import revolution as occ_revolution

        return self._twin(lambda: occ_revolution(self.profile.geom(), self.axis_origin, self.axis_direction))

    def transformed(self, matrix):
        """Similarity maps keep the construct: profile and axis are mapped, and a mirror
        (negative determinant) also reverses the axis so that ``S'(u, v)`` is the image of
        ``S(u, v)`` (OCCT reverses u in the same case); other maps use ``to_nurbs``."""
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            return self.to_nurbs().transformed(m)
        det = np.linalg.det(m[:3, :3])
        axis = transforms.apply_vectors(m, self.axis_direction) * np.sign(det)
        return RevolutionSurface._trusted(self.profile.transformed(m), transforms.apply(m, self.axis_origin), axis, self.u_range)

    def to_nurbs(self) -> BSplineSurface:
        """The exact rational B-spline form (u: rational quadratic arcs; v: the profile's
        B-spline, whose parametrization may differ for conic profiles).

        >>> import numpy as np, surfmod as sm
        >>> s = sm.revolution(sm.Line((1, 0, 0), (1, 0, 2)), (0, 0, 0), (0, 0, 1)).to_nurbs()
        >>> bool(np.allclose(np.hypot(*s.points(1.0, 0.5)[:2]), 1.0))
        True
        """
        return revolve_nurbs(self.profile.to_bspline(), self.axis_origin, self.axis_direction, self.u_range)


def revolution(profile, axis_origin=(0.0, 0.0, 0.0), axis_direction=(0.0, 0.0, 1.0), angle: float = 360.0):
    """Rotate a planar ``profile`` (surfmod curve or build123d Edge/Wire) about an axis in
    its plane by ``angle`` degrees: ``Geom_SurfaceOfRevolution``'s parametrization, u the
    angle in radians in ``[0, radians(angle)]``, v the profile parameter.

    >>> import math, surfmod as sm
    >>> s = sm.revolution(sm.Line((1, 0, 0), (1, 0, 2)), (0, 0, 0), (0, 0, 1))
    >>> s.points(math.pi / 2, 1.0).round(12)
    array([0., 1., 1.])
    """
    curve = as_curve(profile, "profile")
    o = checks.point(axis_origin, "axis_origin")
    a = checks.direction(axis_direction, "axis_direction")
    ang = checks.angle(angle, "angle")
    if not 0.0 < ang <= 360.0:
        raise SurfmodError(f"angle: must lie in (0, 360] degrees, got {ang:g}")
    axis_plane_check(curve, o, a)
    return RevolutionSurface._trusted(curve, o, a, (0.0, math.radians(ang)))
