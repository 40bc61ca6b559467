"""The grid ``us x vs`` of a local-support net in NumPy, for grids too small to wait for
the compiled twin (:mod:`surfmod.eval.tensor_grid_compiled`); the basis and the quotient
rule are those of the scattered points (:mod:`surfmod.eval.scattered`).

>>> import numpy as np
>>> net = np.ones((4, 4, 4)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]; net[..., 2] = 0
>>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
>>> tensor_grid(knots, 3, knots, 3, net, False, np.array([0.5]), np.array([0.25]), 0)[0, 0, 0, 0]
array([1.5 , 0.75, 0.  ])
"""

from __future__ import annotations

import numpy as np

from .rational import surface_quotient
from .scattered import basis_at


def tensor_grid(ku, p, kv, q, ctrl, rational: bool, us, vs, order: int) -> np.ndarray:
    """Partials to ``order`` on the grid ``us x vs``: ``(len(us), len(vs), K, K, 3)``.

    Two stages, as the compiled twin (:mod:`surfmod.eval.tensor_grid_compiled`): the net
    rows the u-points read are contracted with the v-basis once (``rows[r, b, l]``), then
    every u-point combines its ``p + 1`` rows."""
    n, m = ctrl.shape[:2]
    kk, dim = order + 1, 4 if rational else 3
    su, bu = basis_at(ku, p, n, us, order)
    sv, bv = basis_at(kv, q, m, vs, order)
    needed = np.unique((su[:, None] - p + np.arange(p + 1)).ravel())
    local = ctrl[needed][:, :, :dim]  # (R, m, dim): only the rows in use
    rows = np.zeros((needed.size, vs.size, kk, dim))
    for j in range(q + 1):
        rows += bv[None, :, :, j, None] * local[:, sv - q + j, None, :]
    first = np.searchsorted(needed, su - p)
    h = np.zeros((us.size, vs.size, kk, kk, dim))
    for i in range(p + 1):
        h += bu[:, None, :, None, i, None] * rows[first + i][:, :, None, :, :]
    return surface_quotient(h) if rational else h
