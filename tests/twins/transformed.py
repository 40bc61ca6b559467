"""OCCT's transforms of surfaces (``gp_Trsf`` by name, ``gp_GTrsf`` for general affine
maps): the kernel twins of :mod:`surfmod.transforms` that the NumPy maps are checked against."""

from __future__ import annotations

import math

import numpy as np
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_GTrsf, gp_Mat, gp_Pnt, gp_Trsf, gp_XYZ

from surfmod.errors import SurfmodError
from surfmod.occ import arrays
from surfmod.occ.analytic import trsf
from surfmod.occ.geom import downcast_surface
from surfmod.occ.guard import kernel


def named_trsf(kind: str, *args) -> gp_Trsf:
    """An OCCT ``gp_Trsf`` built with its own named setters (independent of surfmod's matrices).

    ``kind``: ``"translation" (vector)``, ``"rotation" (origin, direction, degrees)``,
    ``"mirror" (point, normal)`` (plane symmetry), ``"scale" (center, factor)``.

    >>> named_trsf("translation", (1, 2, 3)).TranslationPart().Coord()
    (1.0, 2.0, 3.0)
    >>> named_trsf("shear", (1, 0, 0))
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: kind: expected translation, rotation, mirror or scale, got 'shear'
    """
    t = gp_Trsf()
    with kernel(f"gp_Trsf ({kind})"):
        if kind == "translation":
            t.SetTranslation(arrays.vec(args[0]))
        elif kind == "rotation":
            o, d, deg = args
            t.SetRotation(gp_Ax1(arrays.pnt(o), gp_Dir(*map(float, d))), math.radians(deg))
        elif kind == "mirror":
            p, n = args
            t.SetMirror(gp_Ax2(arrays.pnt(p), gp_Dir(*map(float, n))))
        elif kind == "scale":
            c, f = args
            t.SetScale(arrays.pnt(c), float(f))
        else:
            raise SurfmodError(f"kind: expected translation, rotation, mirror or scale, got {kind!r}")
    return t


def trsf_matrix(t: gp_Trsf) -> np.ndarray:
    """The 4x4 matrix of a ``gp_Trsf`` (as OCCT applies it to points)."""
    m = np.eye(4)
    for i in range(3):
        for j in range(4):
            m[i, j] = t.Value(i + 1, j + 1)
    return m


def geom_transformed(surf, t: gp_Trsf):
    """``surf.Transformed(t)`` downcast to its concrete ``Geom_*`` class."""
    with kernel("Geom_Surface.Transformed"):
        return downcast_surface(surf.Transformed(t))


def geom_gtransformed(surf, matrix):
    """A general affine map (``gp_GTrsf``, e.g. non-uniform scale) applied to the poles of a
    ``Geom_BSplineSurface`` / ``Geom_BezierSurface`` copy (weights unchanged)."""
    m = np.asarray(matrix, dtype=float)
    g = gp_GTrsf()
    with kernel("gp_GTrsf"):
        g.SetVectorialPart(gp_Mat(*map(float, m[:3, :3].ravel())))
        g.SetTranslationPart(gp_XYZ(*map(float, m[:3, 3])))
        out = downcast_surface(surf.Copy())
        for i in range(1, out.NbUPoles() + 1):
            for j in range(1, out.NbVPoles() + 1):
                xyz = out.Pole(i, j).XYZ()
                g.Transforms(xyz)
                out.SetPole(i, j, gp_Pnt(xyz))
    return out


def transformed(geom, matrix):
    """``geom.Transformed(gp_Trsf(matrix))`` for a similarity matrix (the door's
    :func:`~surfmod.occ.analytic.trsf`)."""
    with kernel("Geom_Geometry.Transformed"):
        return geom.Transformed(trsf(matrix))


def default_x_dir(normal) -> np.ndarray:
    """The X direction ``gp_Ax2(P, N)`` picks for a main direction ``N``: the reference
    of :func:`surfmod.construct.axes.default_x_dir`."""
    with kernel("gp_Ax2"):
        return arrays.xyz(gp_Ax2(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(*map(float, normal))).XDirection())
