"""The ``Curve`` protocol: what every surfmod curve offers (see API.md).

A subclass supplies ``domain``, ``_derivatives(t, order)`` on flat validated parameters,
``geom()`` and ``transformed``; this base derives the rest.  ``to_bspline()`` gives the
exact (possibly rational) B-spline form that surface constructors work with.
"""

from __future__ import annotations

import abc

import numpy as np

from . import checks
from .immutable import Immutable
from .transforms import mirror_matrix, rotation_matrix, scale_matrix, translation_matrix


class Curve(Immutable, abc.ABC):
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

    def _params(self, t):
        tt = checks.parameters(t, "t", self.domain)
        return tt.shape, tt.ravel()

    def points(self, t) -> np.ndarray:
        """Positions, shape ``t.shape + (3,)``.

        >>> import surfmod as sm
        >>> sm.Line((0, 0, 0), (2, 0, 0)).points(1.0)
        array([1., 0., 0.])
        """
        shape, tf = self._params(t)
        return self._derivatives(tf, 0)[:, 0, :].reshape(*shape, 3)

    def derivatives(self, t, order: int = 1) -> np.ndarray:
        """``[..., k, :] = d^k C / dt^k`` for ``k <= order``."""
        order = checks.count(order, "order", minimum=0)
        shape, tf = self._params(t)
        return self._derivatives(tf, order).reshape(*shape, order + 1, 3)

    def tangents(self, t) -> np.ndarray:
        """Unit tangents ``C' / |C'|``."""
        d = self.derivatives(t, 1)[..., 1, :]
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def edge(self):
        """A build123d ``Edge`` over the whole domain."""
        from .occ.topo import edge_from_curve

        t0, t1 = self.domain
        return edge_from_curve(self.geom(), t0, t1)

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

    def translated(self, vector) -> "Curve":
        return self.transformed(translation_matrix(vector))

    def rotated(self, axis_origin, axis_direction, degrees: float) -> "Curve":
        return self.transformed(rotation_matrix(axis_origin, axis_direction, degrees))

    def mirrored(self, point, normal) -> "Curve":
        return self.transformed(mirror_matrix(point, normal))

    def scaled(self, factor, center=(0.0, 0.0, 0.0)) -> "Curve":
        return self.transformed(scale_matrix(factor, center))
