"""The figures that estimate how many triangles a chordal tolerance needs, before asking
BRepMesh for them: per curved face the area of its UV box's patch and a median
curvature, and the shape's bounding-box diagonal.

Each face is read by the one reader (:func:`surfmod.readback.read_surface`) and
sampled through its surfmod surface; cylinders, spheres, cones and tori have the
closed forms of what sampling would give.
"""

from __future__ import annotations

import math
import statistics
import warnings

import numpy as np

from ..construct.elementary import ConicalSurface, CylindricalSurface, SphericalSurface, ToroidalSurface
from ..errors import KernelError, SurfmodError
from ..eval.differential import curvatures, degenerate_mask, raw_normals
from ..readback.readers import read_surface


def shape_figures(shape, samples: int = 5, sample_face=None, uv_bounds: dict | None = None):
    """Per curved face ``(area, median sqrt(|k1| |k2|) with each |k| floored by 1/diagonal)``
    from a ``samples`` x ``samples`` grid over the face's UV box (area of the box's patch:
    at least the face's), and the bounding-box diagonal: enough to estimate how many
    triangles a chordal tolerance needs before asking BRepMesh for them.  Planes need
    no figure (a plane's triangle count does not grow as the tolerance shrinks), and a
    face that repeats an earlier one at an isometric location (assemblies) repeats its
    figure without being sampled again.

    ``sample_face(face, surface, (u0, u1, v0, v1), samples, floor)``, when given, is asked
    first for each curved face and returns its figure (any pair, e.g. a list the caller
    fills in after this returns, to sample all its faces at once), or ``None`` to leave
    the face to the sampling here.  ``uv_bounds``, a dict, receives each sampled face's
    UV box by face hash (for :func:`surfmod.meshing.facemesh.brepmesh`).

    >>> import build123d as bd
    >>> figures, diag = shape_figures(bd.Cylinder(1, 2))
    >>> len(figures), round(diag, 5)  # a 2 x 2 x 2 box (its tolerances added)
    (1, 3.4641)
    """
    from ..occ.mesh import face_instances

    diag = shape_diagonal(shape)
    floor = 1.0 / max(diag, 1e-300)
    figures: list = []
    for face, first in face_instances(shape):
        known = figures[first] if first >= 0 else _face_figure(face, samples, floor, sample_face, uv_bounds)
        figures.append(known)
    return [f for f in figures if f is not False], diag  # False: a plane


def shape_diagonal(shape) -> float:
    """The diagonal of OCCT's quick bounding box of ``shape`` (``BRepBndLib.Add``: from a
    stored triangulation, else the geometry, enlarged by the tolerances): the size that
    relative tolerances refer to."""
    from ..occ.properties import bounding_box

    try:
        lo, hi = bounding_box(shape, optimal=False)
    except KernelError:  # a void box
        raise SurfmodError("shape: is empty") from None
    return float(np.linalg.norm(hi - lo))


def _face_figure(face, samples: int, floor: float, sample_face=None, uv_bounds: dict | None = None):
    """:func:`shape_figures`' figure of one face, or ``False`` for a plane."""
    from ..occ.geom import surface_type
    from ..occ.mesh import face_basis, uv_box

    surf = face_basis(face)
    if surface_type(surf) == "Geom_Plane":
        return False
    u0, u1, v0, v1 = uv_box(face)
    if uv_bounds is not None:
        uv_bounds[face.__hash__()] = (u0, u1, v0, v1)
    figure = sample_face(face, surf, (u0, u1, v0, v1), samples, floor) if sample_face is not None else None
    if figure is not None:
        return figure
    try:
        s = read_surface(surf, (u0, u1, v0, v1))
    except SurfmodError:  # a type the reader does not know: OCCT's partials
        s = None
    if isinstance(s, (CylindricalSurface, SphericalSurface)):
        # closed forms of what the sampled figures below come to (|Su x Sv|, k1, k2)
        r = s.radius
        if isinstance(s, CylindricalSurface):
            return r * (u1 - u0) * (v1 - v0), float(np.sqrt(max(1 / r, floor) * floor))
        return (r * r * (u1 - u0) * float(np.mean(np.cos(np.linspace(v0, v1, samples)))) * (v1 - v0),
                max(1 / r, floor))
    if isinstance(s, (ConicalSurface, ToroidalSurface)):
        # the same for surfaces of revolution whose figures vary along v only: the
        # circle's radius rho(v) gives |Su x Sv| and the parallel's curvature
        # (five samples: plain floats cost less than NumPy's per-call overhead)
        vs = [v0 + (v1 - v0) * k / (samples - 1) for k in range(samples)]
        if isinstance(s, ConicalSurface):
            a, r0 = s.semi_angle, s.radius
            sa, ca = math.sin(a), math.cos(a)
            rows = [(r0 + v * sa, 1.0, ca) for v in vs]  # (rho, |Su x Sv| / |rho|, cos of the normal's tilt)
            k_meridian = 0.0
        else:
            big, r = s.major, s.minor
            rows = [(big + r * math.cos(v), r, math.cos(v)) for v in vs]
            k_meridian = 1.0 / r
        # no curvature at the apex / on the axis (rho = 0)
        vals = [math.sqrt(max(k_meridian, floor) * max(abs(c / rho), floor)) for rho, _, c in rows if rho != 0]
        area = sum(f * abs(rho) for rho, f, _ in rows) / samples * (u1 - u0) * (v1 - v0)
        return area, statistics.median(vals) if vals else floor
    t = np.arange(samples) / (samples - 1)
    uu, vv = np.repeat(u0 + (u1 - u0) * t, samples), np.tile(v0 + (v1 - v0) * t, samples)  # the grid, u-major
    if s is not None:
        ders = s._derivatives(uu, vv, 2)
    else:
        from ..occ.sample import surface_d2

        ders = surface_d2(surf, uu, vv)
    ((area, median),) = partial_figures(ders[None], np.array([(u1 - u0) * (v1 - v0)]), floor)
    return area, median


def partial_figures(ders: np.ndarray, box_areas: np.ndarray, floor: float) -> list[tuple[float, float]]:
    """Per face ``(area of the UV box's patch, median sqrt(|k1| |k2|))`` from its partials
    to order 2 on a sample grid, ``ders (faces, samples, 3, 3, 3)``, and its UV box's
    area ``box_areas (faces,)``: each ``|k|`` floored by ``floor``, the median over the
    samples where the normal is defined (``floor`` where it is nowhere)."""
    area = np.linalg.norm(raw_normals(ders), axis=-1).mean(axis=1) * box_areas
    c = curvatures(ders)
    vals = np.sqrt(np.maximum(np.abs(c.k1), floor) * np.maximum(np.abs(c.k2), floor))
    defined = ~degenerate_mask(ders, 1e-9)
    ok = defined.any(axis=1)
    median = np.full(len(ders), floor)
    with warnings.catch_warnings():  # faces without any defined curvature stay at the floor
        warnings.simplefilter("ignore", RuntimeWarning)
        median[ok] = np.nanmedian(np.where(defined, vals, np.nan)[ok], axis=1)
    return list(zip(area.tolist(), median.tolist()))
