"""The stock after a program as the verifier swept it (:func:`surfmod.cam.verify.verify_job`):
a height field over the stock box and, node by node, how much material stands on the part.

The verifier keeps it with its verdict (``job.verification.stock``), so that what is
pictured (:mod:`surfmod.cam.job_view`) is what was judged, not a second simulation.  It
holds at most ``KEPT_NODES`` nodes: a finer field is kept as the maxima over square blocks
of nodes (the highest stock, the most left), so nothing left is lost from sight.

>>> top = np.array([[1.0, 1.0, 1.0], [1.0, 1.5, 1.0], [1.0, 1.0, 1.0]])
>>> level_part = np.zeros((3, 3))  # at height 0, but for the node (2, 0)
>>> level_part[2, 0] = -np.inf
>>> field = StockField.over_part(top, level_part, (0.0, 0.0), 1.0, 80.0)
>>> field.left.tolist()  # NaN off the part and beside its outline (no slope there)
[[1.0, 1.0, 1.0], [nan, 1.5, 1.0], [nan, nan, 1.0]]
>>> small = field.coarsened(4)
>>> small.top.tolist(), small.left.tolist(), small.origin, small.cell
([[1.5, 1.0], [1.0, 1.0]], [[1.5, 1.0], [nan, 1.0]], (0.5, 0.5), 2.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import checks

#: nodes a kept field holds at most (two float arrays: 16 MB)
KEPT_NODES = 1_000_000


def grid_axes(origin, cell: float, shape) -> tuple[np.ndarray, np.ndarray]:
    """The x and the y of the nodes ``origin + cell * (i, j)`` of an ``(nx, ny)`` grid: the
    stock's height fields (the verifier's, the job's model, the kept field) all stand on one.

    >>> [a.tolist() for a in grid_axes((1.0, 2.0), 0.5, (3, 2))]
    [[1.0, 1.5, 2.0], [2.0, 2.5]]
    """
    return origin[0] + cell * np.arange(shape[0]), origin[1] + cell * np.arange(shape[1])


def grid_points(origin, cell: float, shape) -> np.ndarray:
    """The grid's nodes as ``(nx * ny, 2)`` points, node ``(i, j)`` at row ``i * ny + j``."""
    gx, gy = np.meshgrid(*grid_axes(origin, cell, shape), indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


class NodeGrid:
    """``x`` and ``y`` of a height field ``top`` on the nodes ``origin + cell * (i, j)``
    (:func:`grid_axes`), for the classes that hold one."""

    @property
    def x(self) -> np.ndarray:
        return grid_axes(self.origin, self.cell, self.top.shape)[0]

    @property
    def y(self) -> np.ndarray:
        return grid_axes(self.origin, self.cell, self.top.shape)[1]


@dataclass(frozen=True)
class StockField(NodeGrid):
    """``top`` (nx, ny): the stock's height at the nodes ``origin + cell * (i, j)``;
    ``left``: the material above the part there, measured along the part's normal (the
    height over the part times the cosine of its slope), NaN off the part and on walls
    the height field cannot see."""

    top: np.ndarray
    left: np.ndarray
    origin: tuple
    cell: float

    def __post_init__(self):
        object.__setattr__(self, "top", checks.frozen(self.top))
        object.__setattr__(self, "left", checks.frozen(self.left))

    @classmethod
    def over_part(cls, top: np.ndarray, under: np.ndarray, origin, cell: float, wall_slope: float,
                  max_nodes: int = KEPT_NODES) -> "StockField":
        """The field of ``top`` over a part whose height at its nodes is ``under`` (the
        shape of ``top``, -inf where there is none), at most ``max_nodes`` nodes (see
        :meth:`coarsened`); nodes steeper than ``wall_slope`` degrees are walls."""
        under = np.asarray(under, float).reshape(np.shape(top))
        part = np.where(np.isfinite(under), under, np.nan)
        if min(part.shape) >= 2:
            gx, gy = np.gradient(part, cell)
            cos = 1.0 / np.sqrt(1.0 + gx * gx + gy * gy)  # NaN beside the part's outline too
        else:
            cos = np.where(np.isfinite(part), 1.0, np.nan)
        wall = ~(cos > math.cos(math.radians(wall_slope)))
        left = np.where(wall, np.nan, np.maximum(top - part, 0.0) * cos)
        return cls(*_pooled(np.asarray(top, float), left, (float(origin[0]), float(origin[1])), float(cell),
                            max_nodes))

    def coarsened(self, max_nodes: int) -> "StockField":
        """At most ``max_nodes`` nodes: the maxima over blocks of ``f x f`` nodes (``f`` the
        least that fits), each standing at its block's centre."""
        nx, ny = self.top.shape
        return self if nx * ny <= max_nodes else StockField(*_pooled(self.top, self.left, self.origin, self.cell,
                                                                     max_nodes))


def _pooled(top: np.ndarray, left: np.ndarray, origin: tuple, cell: float, max_nodes: int) -> tuple:
    """``(top, left, origin, cell)`` at most ``max_nodes`` nodes: the maxima over blocks
    of ``f x f`` nodes (``f`` the least that fits), each standing at its block's centre."""
    nx, ny = top.shape
    f = max(1, math.ceil(math.sqrt(nx * ny / max(int(max_nodes), 1))))
    while math.ceil(nx / f) * math.ceil(ny / f) > max_nodes:
        f += 1  # the ceilings of the block counts can pass the square root's guess
    if f == 1:
        return top, left, origin, cell
    shift = 0.5 * (f - 1) * cell
    return _block_max(top, f), _block_max(left, f), (origin[0] + shift, origin[1] + shift), cell * f


def _block_max(a: np.ndarray, f: int) -> np.ndarray:
    """Maxima over ``f x f`` blocks (the last ones cut short), NaN where a block is all NaN."""
    nx, ny = a.shape
    filled = np.pad(np.where(np.isnan(a), -np.inf, a), ((0, -nx % f), (0, -ny % f)), constant_values=-np.inf)
    out = filled.reshape(filled.shape[0] // f, f, filled.shape[1] // f, f).max(axis=(1, 3))
    return np.where(np.isneginf(out), np.nan, out)
