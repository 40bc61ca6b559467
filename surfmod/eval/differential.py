"""Normals and curvatures from first and second partial derivatives (fundamental forms).

Sign convention: the unit normal is ``Su x Sv / |Su x Sv|`` (as OCCT's ``GeomLProp``),
and the second fundamental form is taken against that normal, so a sphere whose normal
points outwards has mean curvature ``-1/R``.  ``k1 >= k2``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Curvatures(NamedTuple):
    """Gaussian and mean curvature and the principal curvatures ``k1 >= k2``.

    >>> import surfmod as sm
    >>> c = sm.sphere(2.0).curvatures(0.3, 0.2)
    >>> [round(abs(float(x)), 12) for x in c]   # sphere: K = 1/r^2, |H| = |k1| = |k2| = 1/r
    [0.25, 0.5, 0.5, 0.5]
    """

    gaussian: np.ndarray
    mean: np.ndarray
    k1: np.ndarray
    k2: np.ndarray


def raw_normals(ders: np.ndarray) -> np.ndarray:
    """``Su x Sv`` (not normalised) from a ``(..., K, K, 3)`` derivative array."""
    return np.cross(ders[..., 1, 0, :], ders[..., 0, 1, :])


def degenerate_mask(ders: np.ndarray, rel: float) -> np.ndarray:
    """True where ``|Su x Sv|`` is negligible against ``max(|Su|, |Sv|)^2`` (or a partial
    vanishes).  The larger partial sets the scale so that a pole where one partial is
    only round-off (``cos(pi/2)``, rational quotients) still counts as degenerate."""
    su = np.linalg.norm(ders[..., 1, 0, :], axis=-1)
    sv = np.linalg.norm(ders[..., 0, 1, :], axis=-1)
    cross = np.linalg.norm(raw_normals(ders), axis=-1)
    scale = np.maximum(np.maximum(su, sv) ** 2, np.finfo(float).tiny)
    return (cross <= rel * scale) | (su * sv == 0.0)


def unit_normals(ders: np.ndarray) -> np.ndarray:
    """Unit normals; callers replace degenerate points beforehand."""
    n = raw_normals(ders)
    norm = np.linalg.norm(n, axis=-1, keepdims=True)
    return n / np.where(norm > 0.0, norm, 1.0)


def curvatures(ders: np.ndarray) -> Curvatures:
    """Curvatures from a derivative array of order >= 2 (``(..., 3, 3, 3)`` or larger).

    The principal curvatures are the eigenvalues of the shape operator written in the
    orthonormal tangent frame ``e1 = Su / |Su|``, ``e2`` (``Sv`` less its ``e1`` part),
    where it is the symmetric ``[[a, b], [b, c]]``: ``H -+ hypot((a - c) / 2, b)``.  The
    textbook ``H -+ sqrt(H^2 - K)`` subtracts two nearly equal numbers near an umbilic
    and keeps only half of the digits there (a relative error ``1e-13`` of the second
    partials became ``3e-7`` in ``k1``, ``k2`` on near-spherical faces; OCCT's
    ``GeomLProp`` solves for the principal directions and keeps them).  ``EG - F^2`` is
    taken as ``|Su x Sv|^2``, which does not cancel on a skewed parametrisation.
    """
    su, sv = ders[..., 1, 0, :], ders[..., 0, 1, :]
    suu, suv, svv = ders[..., 2, 0, :], ders[..., 1, 1, :], ders[..., 0, 2, :]
    cross = raw_normals(ders)
    e = np.einsum("...i,...i->...", su, su)
    f = np.einsum("...i,...i->...", su, sv)
    g = np.einsum("...i,...i->...", sv, sv)
    # non-finite derivatives (a damaged part's geometry) give non-finite curvatures,
    # which callers test for; numpy's warnings about them would only be noise on stderr
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        area = np.sqrt(np.einsum("...i,...i->...", cross, cross))
        n = cross / np.where(area > 0.0, area, 1.0)[..., None]
        l_ = np.einsum("...i,...i->...", suu, n)
        m_ = np.einsum("...i,...i->...", suv, n)
        n_ = np.einsum("...i,...i->...", svv, n)
        det = np.where(area > 0.0, area * area, np.finfo(float).tiny)
        gauss = (l_ * n_ - m_ * m_) / det
        mean = (e * n_ - 2.0 * f * m_ + g * l_) / (2.0 * det)
        # the shape operator in the frame (e1, e2): a = L / E, b, c the normal curvature along e2
        # (written with F / E: no fourth powers of the partials, which overflow at 1e70)
        slant = f / np.where(e > 0.0, e, np.finfo(float).tiny)
        a = l_ / np.where(e > 0.0, e, np.finfo(float).tiny)
        b = (m_ - l_ * slant) / np.sqrt(det)
        c = (l_ * f * slant - 2.0 * m_ * f + n_ * e) / det
        disc = np.hypot(0.5 * (a - c), b)
        return Curvatures(gauss, mean, mean + disc, mean - disc)
