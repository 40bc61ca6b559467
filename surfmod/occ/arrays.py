"""NumPy <-> OCCT container conversions (TColgp / TColStd arrays, knots + multiplicities)."""

from __future__ import annotations

from itertools import chain

import numpy as np
from OCP.gp import gp_Pnt, gp_Vec

from .bindings import (
    TColgp_Array1OfPnt,
    TColgp_Array2OfPnt,
    TColStd_Array1OfInteger,
    TColStd_Array1OfReal,
    TColStd_Array2OfReal,
)


def pnt(p) -> gp_Pnt:
    return gp_Pnt(float(p[0]), float(p[1]), float(p[2]))


def vec(p) -> gp_Vec:
    return gp_Vec(float(p[0]), float(p[1]), float(p[2]))


def xyz(p) -> np.ndarray:
    """A gp_Pnt/gp_Vec/gp_Dir as a NumPy array."""
    return np.array([p.X(), p.Y(), p.Z()])


def xyz_many(points, n: int) -> np.ndarray:
    """``n`` gp_Pnt/gp_Vec from an iterable as an ``(n, 3)`` array, in one ``fromiter``
    over their ``Coord()`` tuples (no array per point: a third of the time of
    ``np.array([xyz(p) ...])`` on an edge's samples).

    >>> xyz_many((gp_Pnt(i, 0, 1) for i in range(2)), 2).tolist()
    [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0]]
    """
    return np.fromiter(chain.from_iterable(p.Coord() for p in points), float, 3 * n).reshape(n, 3)


def points_1d(points: np.ndarray) -> TColgp_Array1OfPnt:
    arr = TColgp_Array1OfPnt(1, len(points))
    for i, p in enumerate(points, start=1):
        arr.SetValue(i, pnt(p))
    return arr


def points_2d(net: np.ndarray) -> TColgp_Array2OfPnt:
    n, m = net.shape[:2]
    arr = TColgp_Array2OfPnt(1, n, 1, m)
    for i in range(n):
        for j in range(m):
            arr.SetValue(i + 1, j + 1, pnt(net[i, j]))
    return arr


def reals_1d(values) -> TColStd_Array1OfReal:
    values = np.asarray(values, dtype=float)
    arr = TColStd_Array1OfReal(1, len(values))
    for i, x in enumerate(values, start=1):
        arr.SetValue(i, float(x))
    return arr


def ints_1d(values) -> TColStd_Array1OfInteger:
    arr = TColStd_Array1OfInteger(1, len(values))
    for i, x in enumerate(values, start=1):
        arr.SetValue(i, int(x))
    return arr


def reals_2d(values: np.ndarray) -> TColStd_Array2OfReal:
    n, m = values.shape
    arr = TColStd_Array2OfReal(1, n, 1, m)
    for i in range(n):
        for j in range(m):
            arr.SetValue(i + 1, j + 1, float(values[i, j]))
    return arr


def knots_and_mults(flat_knots: np.ndarray):
    """A full knot vector -> OCCT's (distinct knots, multiplicities) pair."""
    values, counts = np.unique(np.asarray(flat_knots, dtype=float), return_counts=True)
    return reals_1d(values), ints_1d(counts)
