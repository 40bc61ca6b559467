"""OCCT's side of meshing and display: BRepMesh triangulations with their (u, v) nodes,
per-face surfaces for measuring chordal deviation, iso-curves (``UIso``/``VIso``) and
the figures needed to estimate a triangle count before meshing.

The plain Python loops here run over OCCT calls (one per node or per sample); they are
the kernel boundary and the measurement side, not a NumPy evaluation path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SurfmodError
from .guard import kernel


@dataclass
class FaceMesh:
    """One face's BRepMesh triangulation: 3-D ``nodes`` (global coordinates), ``uv``
    nodes on the face's surface, ``triangles`` oriented outwards (face orientation
    applied), the face's ``surface`` (global coordinates), its ``face`` and ``bounds``."""

    nodes: np.ndarray
    uv: np.ndarray
    triangles: np.ndarray
    surface: object
    face: object
    bounds: tuple


def clean(shape) -> None:
    """Drop any triangulation stored on ``shape`` so the next BRepMesh starts afresh."""
    from OCP.BRepTools import BRepTools

    from .topo import wrapped

    with kernel("BRepTools.Clean"):
        BRepTools.Clean_s(wrapped(shape))


def brepmesh(shape, deflection: float, angular: float = 0.5, *, relative: bool = False) -> list[FaceMesh]:
    """Run ``BRepMesh_IncrementalMesh`` (after clearing old triangulations) and return the
    per-face triangulations.  BRepMesh discretizes each edge once, so nodes of faces that
    share an edge coincide bit for bit."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_REVERSED
    from OCP.TopLoc import TopLoc_Location

    from .topo import faces_of, wrapped

    shp = wrapped(shape)
    clean(shp)
    out = []
    with kernel("BRepMesh_IncrementalMesh"):
        BRepMesh_IncrementalMesh(shp, float(deflection), bool(relative), float(angular), False)
        for face in faces_of(shp):
            loc = TopLoc_Location()
            tri = BRep_Tool.Triangulation_s(face, loc)
            if tri is None or tri.NbTriangles() == 0:
                continue
            trsf = loc.Transformation()
            n = tri.NbNodes()
            nodes = np.empty((n, 3))
            uv = np.full((n, 2), np.nan)
            has_uv = tri.HasUVNodes()
            for i in range(1, n + 1):
                p = tri.Node(i).Transformed(trsf)
                nodes[i - 1] = (p.X(), p.Y(), p.Z())
                if has_uv:
                    q = tri.UVNode(i)
                    uv[i - 1] = (q.X(), q.Y())
            idx = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)], dtype=np.int64) - 1
            if face.Orientation() == TopAbs_REVERSED:
                idx = idx[:, ::-1]
            surf = BRep_Tool.Surface_s(face)
            bounds = tuple(float(b) for b in BRepTools.UVBounds_s(face))
            out.append(FaceMesh(nodes, uv, idx, surf, face, bounds))
    if not out:
        raise SurfmodError("shape: has no faces to triangulate")
    return out


def surface_d1(surf, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``(N, 2, 2, 3)`` position and first partials of a ``Geom_Surface`` from ``D1``
    (entry ``[1, 1]`` is left zero)."""
    from OCP.gp import gp_Pnt, gp_Vec

    out = np.zeros((len(u), 2, 2, 3))
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    with kernel("Geom_Surface.D1"):
        for a, (uu, vv) in enumerate(zip(u, v)):
            surf.D1(float(uu), float(vv), p, du, dv)
            out[a, 0, 0] = (p.X(), p.Y(), p.Z())
            out[a, 1, 0] = (du.X(), du.Y(), du.Z())
            out[a, 0, 1] = (dv.X(), dv.Y(), dv.Z())
    return out


def analytic_distances(surf, points: np.ndarray) -> np.ndarray | None:
    """Closed-form distance from ``points`` to an untrimmed plane, cylinder, sphere or
    torus (``None`` for any other surface type)."""
    from .geom import downcast_surface, surface_type

    name = surface_type(surf)
    if name not in ("Geom_Plane", "Geom_CylindricalSurface", "Geom_SphericalSurface", "Geom_ToroidalSurface"):
        return None
    s = downcast_surface(surf)
    with kernel(f"{name} parameters"):
        ax = s.Position()
        o = np.array([ax.Location().X(), ax.Location().Y(), ax.Location().Z()])
        d = ax.Direction()
        z = np.array([d.X(), d.Y(), d.Z()])
        rel = points - o
        h = rel @ z
        if name == "Geom_Plane":
            return np.abs(h)
        if name == "Geom_SphericalSurface":
            return np.abs(np.linalg.norm(rel, axis=1) - s.Radius())
        radial = np.linalg.norm(rel - h[:, None] * z, axis=1)
        if name == "Geom_CylindricalSurface":
            return np.abs(radial - s.Radius())
        return np.abs(np.hypot(radial - s.MajorRadius(), h) - s.MinorRadius())


def iso_curve(surf, direction: int, value: float):
    """OCCT's exact iso-parametric curve: ``UIso(value)`` (direction 0: u fixed, a curve
    in v) or ``VIso(value)`` (direction 1)."""
    with kernel("Geom_Surface.UIso/VIso"):
        return surf.UIso(float(value)) if direction == 0 else surf.VIso(float(value))


def curve_points(curve, t: np.ndarray) -> np.ndarray:
    """``(N, 3)`` points of a ``Geom_Curve`` (``Value`` per parameter)."""
    with kernel("Geom_Curve.Value"):
        out = np.empty((len(t), 3))
        for a, tt in enumerate(t):
            p = curve.Value(float(tt))
            out[a] = (p.X(), p.Y(), p.Z())
        return out


def shape_figures(shape, samples: int = 9):
    """Per face ``(area, mean sqrt(|k1| |k2|) with each |k| floored by 1/diagonal)`` and the
    bounding-box diagonal: enough to estimate how many triangles a chordal tolerance
    needs before asking BRepMesh for them."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.GeomLProp import GeomLProp_SLProps

    from .topo import faces_of, wrapped

    shp = wrapped(shape)
    with kernel("shape figures (BRepGProp, GeomLProp)"):
        box = Bnd_Box()
        BRepBndLib.Add_s(shp, box)
        if box.IsVoid():
            raise SurfmodError("shape: is empty")
        x0, y0, z0, x1, y1, z1 = box.Get()
        diag = float(np.linalg.norm([x1 - x0, y1 - y0, z1 - z0]))
        floor = 1.0 / max(diag, 1e-300)
        figures = []
        from OCP.BRep import BRep_Tool
        from OCP.BRepTools import BRepTools

        for face in faces_of(shp):
            props = GProp_GProps()
            BRepGProp.SurfaceProperties_s(face, props)
            area = abs(props.Mass())
            surf = BRep_Tool.Surface_s(face)
            u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
            lp = GeomLProp_SLProps(surf, 2, 1e-9)
            vals = []
            for uu in np.linspace(u0, u1, samples):
                for vv in np.linspace(v0, v1, samples):
                    lp.SetParameters(float(uu), float(vv))
                    if lp.IsCurvatureDefined():
                        k1, k2 = abs(lp.MaxCurvature()), abs(lp.MinCurvature())
                        vals.append(np.sqrt(max(k1, floor) * max(k2, floor)))
            figures.append((area, float(np.mean(vals)) if vals else floor))
    return figures, diag


def max_tolerance(shape) -> float:
    """Largest vertex/edge/face tolerance stored in a shape (how far OCCT allows its
    topology to stray from the geometry)."""
    from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance

    from .topo import wrapped

    with kernel("ShapeAnalysis_ShapeTolerance"):
        return float(ShapeAnalysis_ShapeTolerance().Tolerance(wrapped(shape), 1))
