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


# points per block of the surface quotient rule: the temporaries stay in cache
_BLOCK = 1 << 14


def surface_quotient(hders: np.ndarray) -> np.ndarray:
    """``(..., K, K, 4)`` homogeneous mixed partials -> ``(..., K, K, 3)`` Cartesian ones.

    Every entry of the square is exact (also ``k + l > K - 1``), as the rule needs only
    lower entries of the same square.  The work is done on planes: with the derivative
    axes moved to the front, every arithmetic step runs over an array of points, which
    is fast when the points are the contiguous axis (the layout of the scattered and the
    planar grid evaluators); blocks of points keep the temporaries in cache.  The result
    is the matching moved-axis view.
    """
    order = hders.shape[-2] - 1
    if order == 0:  # positions only: one division, the common (and large-grid) case
        return hders[..., :3] / hders[..., 3:4]
    planes = np.moveaxis(hders, (-3, -2, -1), (0, 1, 2))  # (K, K, 4, ...)
    out = np.empty(planes.shape[:2] + (3,) + planes.shape[3:])
    lead = planes.shape[3:]
    rows = max(1, _BLOCK // max(1, int(np.prod(lead[1:]))))
    for r0 in range(0, lead[0] if lead else 1, rows):
        block = (slice(None),) * 3 + ((slice(r0, r0 + rows),) if lead else ())
        _quotient_planes(planes[block], out[block], order)
    return np.moveaxis(out, (0, 1, 2), (-3, -2, -1))


def _quotient_planes(planes, out, order: int) -> None:
    """The quotient rule on planes ``(K, K, 4, ...)`` written into ``out (K, K, 3, ...)``."""
    a, w = planes[:, :, :3], planes[:, :, 3:4]
    inv_w0 = 1.0 / w[0, 0]
    term = np.empty(out.shape[2:])  # (3, points...)
    for k in range(order + 1):
        for l in range(order + 1):
            acc = out[k, l]
            acc[...] = a[k, l]
            lower = [(0, j, comb(l, j)) for j in range(1, l + 1)]
            lower += [(i, j, comb(k, i) * comb(l, j)) for i in range(1, k + 1) for j in range(l + 1)]
            for i, j, c in lower:
                np.multiply(out[k - i, l - j], w[i, j], out=term)
                if c != 1:
                    term *= c
                acc -= term
            acc *= inv_w0
