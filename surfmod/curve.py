"""The ``Curve`` protocol: what every surfmod curve offers (see API.md).

A subclass supplies ``domain``, ``_derivatives(t, order)`` on flat validated parameters,
``geom()`` and ``transformed``; this base derives the rest.  ``to_bspline()`` gives the
exact (possibly rational) B-spline form that surface constructors work with.
"""

from __future__ import annotations

import abc

import numpy as np

from . import checks, pictures
from .errors import SurfmodError
from .immutable import Immutable
from .transforms import Transformable


def _finite(out: np.ndarray, t: np.ndarray, what: str) -> np.ndarray:
    """``out`` when finite; else a ``SurfmodError`` naming the first bad parameter."""
    if np.isfinite(out).all():
        return out
    i = int(np.argmax(~np.isfinite(out.reshape(len(out), -1)).all(axis=1)))
    raise SurfmodError(f"t: the {what} at t = {t[i]:.17g} are not finite (the curve is singular or overflows there)")


class Curve(Transformable, Immutable, abc.ABC):
    """Base of every parametric curve in surfmod.

    Curves evaluate like surfaces, vectorized over the parameter:

    >>> import surfmod as sm
    >>> c = sm.BezierCurve([(0, 0, 0), (1, 2, 0), (2, 0, 0)])
    >>> c.points([0.0, 0.5, 1.0])
    array([[0., 0., 0.],
           [1., 1., 0.],
           [2., 0., 0.]])
    """

    exact_in_occt: bool = True
    occt_construct: str = "Geom_Curve"

    @property
    @abc.abstractmethod
    def domain(self) -> tuple[float, float]:
        """``(t0, t1)``."""

    @abc.abstractmethod
    def _derivatives(self, t: np.ndarray, order: int) -> np.ndarray:
        """``(N, order+1, 3)`` for flat in-domain parameters."""

    @abc.abstractmethod
    def geom(self):
        """The OCCT ``Geom_Curve`` with the same parametrization."""

    @abc.abstractmethod
    def transformed(self, matrix) -> "Curve":
        """A new curve with the 4x4 affine ``matrix`` applied to its definition."""

    @abc.abstractmethod
    def to_bspline(self):
        """The exact B-spline/NURBS form (parametrization may differ for conics)."""

    def _params(self, t, per_point: int = 1, max_points: int = checks.MAX_POINTS):
        tt = checks.parameters(t, "t", self.domain)
        checks.work(float(tt.size) * per_point, max_points, "max_points", f"evaluating {tt.size} parameters")
        return tt.shape, tt.ravel()

    def points(self, t, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Positions, shape ``t.shape + (3,)``.

        >>> import surfmod as sm
        >>> sm.Line((0, 0, 0), (2, 0, 0)).points(1.0)
        array([1., 0., 0.])
        """
        shape, tf = self._params(t, 1, max_points)
        return _finite(self._evaluate(tf, 0)[:, 0, :], tf, "points").reshape(*shape, 3)

    def derivatives(self, t, order: int = 1, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """``[..., k, :] = d^k C / dt^k`` for ``k <= order`` (``order`` at most
        ``checks.MAX_DERIVATIVE_ORDER``).

        >>> import surfmod as sm
        >>> sm.Line((0, 0, 0), (2, 0, 0)).derivatives(0.5, order=2)[1:]   # unit speed
        array([[1., 0., 0.],
               [0., 0., 0.]])
        """
        order = checks.derivative_order(order)
        shape, tf = self._params(t, order + 1, max_points)
        return _finite(self._evaluate(tf, order), tf, "derivatives").reshape(*shape, order + 1, 3)

    def tangents(self, t, *, max_points: int = checks.MAX_POINTS) -> np.ndarray:
        """Unit tangents ``C' / |C'|``; a parameter where the curve stops (``C' = 0``)
        raises ``SurfmodError`` instead of returning NaN."""
        shape, tf = self._params(t, 2, max_points)
        d = self._evaluate(tf, 1)[:, 1, :]
        speed = np.linalg.norm(d, axis=-1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            return _finite(d / speed, tf, "tangents").reshape(*shape, 3)

    def _evaluate(self, tf: np.ndarray, order: int) -> np.ndarray:
        """``_derivatives`` that also takes empty arrays (subclasses need not)."""
        if tf.size == 0:
            return np.empty((0, order + 1, 3))
        return self._derivatives(tf, order)

    def edge(self):
        """A build123d ``Edge`` over the whole domain."""
        from .occ.topo import edge_from_curve

        t0, t1 = self.domain
        return edge_from_curve(self.geom(), t0, t1)

    def _repr_png_(self) -> bytes | None:
        """A picture for Jupyter: the curve as a line (see :func:`surfmod.meshing.render.png_bytes`)."""
        return pictures.repr_png(self)

    @property
    def breaks(self) -> np.ndarray:
        """Parameters where the curve may lose smoothness (the domain ends; a B-spline adds
        its distinct interior knots)."""
        return np.array(self.domain, dtype=float)

    def length(self, samples: int = 16) -> float:
        """Arc length by Gauss-Legendre quadrature with ``samples`` nodes on every piece
        between ``breaks`` (exact for polylines, converges spectrally on smooth pieces).

        >>> import surfmod as sm
        >>> sm.BSplineCurve([(0, 0, 0), (3, 0, 0), (3, 4, 0)], 1).length()
        7.0
        """
        samples = checks.count(samples, "samples", minimum=1)
        nodes, wts = np.polynomial.legendre.leggauss(samples)
        b = self.breaks
        half = (b[1:, None] - b[:-1, None]) / 2
        t = ((b[1:, None] + b[:-1, None]) / 2 + half * nodes).ravel()
        speed = np.linalg.norm(self._derivatives(t, 1)[:, 1, :], axis=-1)
        return float(np.sum((half * wts).ravel() * speed))
