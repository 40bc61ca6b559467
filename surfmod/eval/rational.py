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
    lower entries of the same square.
    """
    aders, w = hders[..., :3], hders[..., 3]
    order = hders.shape[-2] - 1
    out = np.zeros_like(aders)
    w0 = w[..., 0, 0, None]
    for k in range(order + 1):
        for l in range(order + 1):
            acc = aders[..., k, l, :].copy()
            for j in range(1, l + 1):
                acc -= comb(l, j) * w[..., 0, j, None] * out[..., k, l - j, :]
            for i in range(1, k + 1):
                acc -= comb(k, i) * w[..., i, 0, None] * out[..., k - i, l, :]
                for j in range(1, l + 1):
                    acc -= comb(k, i) * comb(l, j) * w[..., i, j, None] * out[..., k - i, l - j, :]
            out[..., k, l, :] = acc / w0
    return out


def planes_quotient(planes: dict, order: int) -> dict:
    """The quotient rule on grid planes ``{(k, l): (nu, nv, 4)}`` -> ``(nu, nv, 3)``.

    Same formula as :func:`surface_quotient`, laid out for the grid fast path.
    """
    out = {}
    w0 = planes[0, 0][..., 3:4]
    for k in range(order + 1):
        for l in range(order + 1):
            acc = planes[k, l][..., :3].copy()
            for j in range(1, l + 1):
                acc -= comb(l, j) * planes[0, j][..., 3:4] * out[k, l - j]
            for i in range(1, k + 1):
                acc -= comb(k, i) * planes[i, 0][..., 3:4] * out[k - i, l]
                for j in range(1, l + 1):
                    acc -= comb(k, i) * comb(l, j) * planes[i, j][..., 3:4] * out[k - i, l - j]
            acc /= w0
            out[k, l] = acc
    return out
