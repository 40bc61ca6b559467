"""The quotient rule for rational curves and surfaces (Piegl & Tiller A4.2 / A4.4).

Input: derivatives of the homogeneous map ``(w x, w y, w z, w)``; output: derivatives of
the Cartesian map.  Vectorized over points; loops over derivative orders only.
"""

from __future__ import annotations

from math import comb

import numpy as np


def curve_quotient(hders: np.ndarray) -> np.ndarray:
    """``(N, K, 4)`` homogeneous derivatives -> ``(N, K, 3)`` Cartesian derivatives."""
    aders, wders = hders[..., :3], hders[..., 3]
    out = np.empty_like(aders)
    for k in range(hders.shape[1]):
        acc = aders[:, k].copy()
        for i in range(1, k + 1):
            acc -= comb(k, i) * wders[:, i, None] * out[:, k - i]
        out[:, k] = acc / wders[:, 0, None]
    return out


def surface_quotient(hders: np.ndarray) -> np.ndarray:
    """``(..., K, K, 4)`` homogeneous mixed partials -> ``(..., K, K, 3)`` Cartesian ones.

    Every entry of the square is exact (also ``k + l > K - 1``), as the rule needs only
    lower entries of the same square.  The work is done on planes: with the derivative
    axes moved to the front, every arithmetic step runs over one array of points, which
    is fast when the points are the contiguous axis (the layout of the scattered and the
    planar grid evaluators); the result is the matching moved-axis view.
    """
    order = hders.shape[-2] - 1
    if order == 0:  # positions only: one division, the common (and large-grid) case
        return hders[..., :3] / hders[..., 3:4]
    planes = np.moveaxis(hders, (-3, -2, -1), (0, 1, 2))  # (K, K, 4, ...)
    a, w = planes[:, :, :3], planes[:, :, 3:4]
    out = np.empty(a.shape)
    inv_w0 = 1.0 / w[0, 0]
    for k in range(order + 1):
        for l in range(order + 1):
            acc = a[k, l].copy()
            for j in range(1, l + 1):
                acc -= comb(l, j) * w[0, j] * out[k, l - j]
            for i in range(1, k + 1):
                acc -= comb(k, i) * w[i, 0] * out[k - i, l]
                for j in range(1, l + 1):
                    acc -= (comb(k, i) * comb(l, j)) * w[i, j] * out[k - i, l - j]
            np.multiply(acc, inv_w0, out=out[k, l])
    return np.moveaxis(out, (0, 1, 2), (-3, -2, -1))
