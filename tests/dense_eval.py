"""The dense NumPy evaluator of surfmod's first round, kept as a test oracle beside
``reference.py``: dense basis matrices and two BLAS products per grid, an algorithm
independent of the local-support paths (surfmod/eval/scattered.py, tensor_grid.py and their compiled
kernels) that the library uses.

>>> import numpy as np
>>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
>>> knots = np.array([0, 0, 0, 0, 1, 1, 1, 1.0])
>>> surface_grid(knots, 3, knots, 3, net, np.array([0.5]), np.array([0.25]), 0)[0, 0, 0, 0]
array([1.5 , 0.75, 0.  ])
"""

from __future__ import annotations

import numpy as np

from surfmod.eval.basis import basis_matrix


def surface_grid(knots_u, p, knots_v, q, ctrl, us, vs, order, *, planar: bool = False):
    """Mixed partials on the grid ``us x vs``: ``(len(us), len(vs), K, K, dim)``, K = order+1.

    Two BLAS products and nothing else.  First the small contraction over v,
    ``W[i, b, l, :] = sum_j Bv_l[b, j] P[i, j, :]`` (size n x nv x K x dim), then one large
    GEMM of the stacked u-basis ``Bu[(a, k), i]`` with it.  The GEMM writes its output in
    the memory order ``(a, k, b, l, dim)`` (point-major: the natural layout for
    positions), or with ``planar`` in the order ``(k, a, l, dim, b)``, where every partial
    and coordinate is a plane with contiguous rows (what the rational quotient wants).
    The result is a transposed *view* of that block: the big array is written once.
    """
    n, m, dim = ctrl.shape
    k_ = order + 1
    bu = basis_matrix(knots_u, p, n, us, order)  # (K, nu, n)
    bv = basis_matrix(knots_v, q, m, vs, order)  # (K, nv, m)
    nu, nv = bu.shape[1], bv.shape[1]
    by_v = ctrl.transpose(1, 0, 2).reshape(m, n * dim)
    w = (bv.reshape(k_ * nv, m) @ by_v).reshape(k_, nv, n, dim)
    if planar:
        w = w.transpose(2, 0, 3, 1).reshape(n, k_ * dim * nv)
        block = (bu.reshape(k_ * nu, n) @ w).reshape(k_, nu, k_, dim, nv)
        return block.transpose(1, 4, 0, 2, 3)
    w = w.transpose(2, 1, 0, 3).reshape(n, nv * k_ * dim)
    stacked_u = bu.transpose(1, 0, 2).reshape(nu * k_, n)
    block = (stacked_u @ w).reshape(nu, k_, nv, k_, dim)
    return block.transpose(0, 2, 1, 3, 4)
