"""Elementary curves: straight line segments (conics live in ``construct/conics.py``)."""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve


class Line(Curve):
    """A straight segment, OCCT's ``Geom_Line`` parametrization ``O + t D`` (``D`` unit)
    over a parameter range.

    ``Line(p0, p1)`` runs from ``p0`` (``t = 0``) to ``p1`` (``t = |P1 - P0|``), arc-length
    parametrized like build123d's line edges; ``Line.through(origin, direction, t_range)``
    is the same construct over any range (how OCCT faces and edges carry lines).

    >>> import surfmod as sm
    >>> sm.Line((0, 0, 0), (0, 3, 4)).domain
    (0.0, 5.0)
    >>> sm.Line.through((0, 0, 0), (1, 0, 0), (-1, 2)).points(-1.0)
    array([-1.,  0.,  0.])
    """

    occt_construct = "Geom_TrimmedCurve(Geom_Line)"

    def __init__(self, p0, p1):
        a, b = checks.point(p0, "p0"), checks.point(p1, "p1")
        length = float(np.linalg.norm(b - a))
        if length <= 1e-12 * max(1.0, np.abs(a).max()):
            raise SurfmodError("p1: coincides with p0, a line needs two distinct points")
        self.origin = checks.frozen(a)
        self.direction = checks.frozen((b - a) / length)
        self._domain = (0.0, length)

    @classmethod
    def through(cls, origin, direction, t_range=(0.0, 1.0)) -> "Line":
        """The line ``origin + t * direction`` (direction normalized) for ``t`` in ``t_range``."""
        o = checks.point(origin, "origin")
        d = checks.direction(direction, "direction")
        return cls._construct_fast(
            origin=checks.frozen(o), direction=checks.frozen(d), _domain=checks.interval(t_range, "t_range")
        )

    @property
    def domain(self):
        return self._domain

    @property
    def p0(self) -> np.ndarray:
        """The start point (``t = t0``)."""
        return self.origin + self._domain[0] * self.direction

    @property
    def p1(self) -> np.ndarray:
        """The end point (``t = t1``)."""
        return self.origin + self._domain[1] * self.direction

    def _derivatives(self, t, order):
        out = np.zeros((t.size, order + 1, 3))
        out[:, 0] = self.origin + t[:, None] * self.direction
        if order >= 1:
            out[:, 1] = self.direction
        return out

    def geom(self):
        from ..occ.analytic import infinite_line, trimmed

        return trimmed(infinite_line(self.origin, self.direction), *self._domain)

    def to_bspline(self) -> BSplineCurve:
        """Degree-1 B-spline with the same parametrization."""
        t0, t1 = self._domain
        return BSplineCurve._trusted(np.array([self.p0, self.p1]), 1, np.array([t0, t0, t1, t1]))

    def transformed(self, matrix):
        """Similarities keep the line (``t`` scales by ``|s|``, as in OCCT); other affine
        maps give the mapped degree-1 B-spline with the same parameter."""
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            return self.to_bspline().transformed(m)
        d = transforms.apply_vectors(m, self.direction)
        s = float(np.linalg.norm(d))
        t0, t1 = self._domain
        return Line.through(transforms.apply(m, self.origin), d / s, (t0 * s, t1 * s))
