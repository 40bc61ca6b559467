"""Quadrics of the lecture: sphere and torus with OCCT's own parametrizations, and the
ellipsoid as an exact rational B-spline (a non-uniformly scaled NURBS sphere).
Each has its implicit form ``F(x, y, z)`` (zero on the surface)."""

from __future__ import annotations

import numpy as np

from .. import checks
from ..nets.bspline import BSplineSurface
from .elementary import SphericalSurface, ToroidalSurface


def sphere(radius, center=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), x_dir=None) -> SphericalSurface:
    """The sphere ``C + R cos v (cos u X + sin u Y) + R sin v Z`` (``Geom_SphericalSurface``),
    u in ``[0, 2 pi]``, v in ``[-pi/2, pi/2]``.

    >>> import numpy as np, surfmod as sm
    >>> s = sm.sphere(2.0, center=(1, 0, 0))
    >>> float(np.abs(s.implicit(s.points(0.4, 0.3)))) < 1e-12
    True
    """
    return SphericalSurface(radius, center, axis, x_dir)


def torus(major, minor, center=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), x_dir=None) -> ToroidalSurface:
    """The ring torus ``C + (R + r cos v)(cos u X + sin u Y) + r sin v Z``
    (``Geom_ToroidalSurface``), u, v in ``[0, 2 pi]``; ``minor < major``.

    >>> import surfmod as sm
    >>> sm.torus(3.0, 1.0).points(0.0, 3.141592653589793).round(12)
    array([2., 0., 0.])
    """
    return ToroidalSurface(major, minor, center, axis, x_dir)


class Ellipsoid(BSplineSurface):
    """``(x/rx)^2 + (y/ry)^2 + (z/rz)^2 = 1`` about ``center``, as an exact rational
    B-spline (degree 2 x 2, 9 x 5 control points): the NURBS unit sphere (u around z,
    v from the south to the north pole) scaled by ``(rx, ry, rz)``.  OCCT counterpart:
    ``Geom_BSplineSurface`` with the same poles, weights and knots.

    >>> import surfmod as sm, numpy as np
    >>> e = sm.ellipsoid(3, 2, 1)
    >>> p = e.grid(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    >>> bool(np.allclose((p[..., 0] / 3) ** 2 + (p[..., 1] / 2) ** 2 + p[..., 2] ** 2, 1))
    True
    """

    occt_construct = "Geom_BSplineSurface (rational, exact ellipsoid)"

    def implicit(self, xyz) -> np.ndarray:
        """``(x/rx)^2 + (y/ry)^2 + (z/rz)^2 - 1`` relative to the centre."""
        p = (np.asarray(xyz, dtype=float) - self.center) / self.radii
        return np.sum(p * p, axis=-1) - 1.0

    def volume(self) -> float:
        """``4/3 pi rx ry rz``."""
        return 4.0 / 3.0 * np.pi * float(np.prod(self.radii))


def ellipsoid(rx, ry, rz, center=(0.0, 0.0, 0.0)) -> Ellipsoid:
    """The ellipsoid with semi-axes ``rx, ry, rz`` along x, y, z as an exact NURBS.

    >>> import numpy as np, surfmod as sm
    >>> e = sm.ellipsoid(3, 2, 1)
    >>> float(np.abs(e.implicit(e.points(0.3, 0.6))).max()) < 1e-12
    True
    """
    radii = np.array([checks.positive(rx, "rx"), checks.positive(ry, "ry"), checks.positive(rz, "rz")])
    c = checks.point(center, "center")
    unit = SphericalSurface(1.0).to_nurbs()
    obj = Ellipsoid._trusted(unit.control_points * radii + c, unit.degree, unit.knots, unit.weights)
    obj.radii = checks.frozen(radii)
    obj.center = checks.frozen(c)
    return obj
