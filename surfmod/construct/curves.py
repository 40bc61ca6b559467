"""Elementary curves: straight line segments (more conics live in ``build/conics.py``)."""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve


class Line(Curve):
    """The segment ``P0 + t * (P1 - P0) / |P1 - P0|`` for ``t`` in ``[0, |P1 - P0|]``.

    Arc-length parametrized, like OCCT's ``Geom_Line`` and build123d's line edges.

    >>> import surfmod as sm
    >>> sm.Line((0, 0, 0), (0, 3, 4)).domain
    (0.0, 5.0)
    """

    occt_construct = "Geom_TrimmedCurve(Geom_Line)"

    def __init__(self, p0, p1):
        a, b = checks.point(p0, "p0"), checks.point(p1, "p1")
        length = float(np.linalg.norm(b - a))
        if length <= 1e-12 * max(1.0, np.abs(a).max()):
            raise SurfmodError("p1: coincides with p0, a line needs two distinct points")
        self.p0, self.p1 = checks.frozen(a), checks.frozen(b)
        self._length = length
        self.direction = checks.frozen((b - a) / length)

    @property
    def domain(self):
        return 0.0, self._length

    def _derivatives(self, t, order):
        out = np.zeros((t.size, order + 1, 3))
        out[:, 0] = self.p0 + t[:, None] * self.direction
        if order >= 1:
            out[:, 1] = self.direction
        return out

    def geom(self):
        from ..occ.curves import line

        return line(self.p0, self.direction, self._length)

    def transformed(self, matrix) -> "Line":
        m = transforms.affine(matrix)
        return Line(transforms.apply(m, self.p0), transforms.apply(m, self.p1))

    def to_bspline(self) -> BSplineCurve:
        """Degree-1 B-spline with the same (arc-length) parametrization."""
        return BSplineCurve._trusted(np.array([self.p0, self.p1]), 1, np.array([0.0, 0.0, self._length, self._length]))
