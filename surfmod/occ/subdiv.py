"""Sewing subdivision-limit patches into a shell and a solid (``BRepBuilderAPI_Sewing``), and
how the sewn faces meet (OCCT side of surfmod.subdiv)."""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepAdaptor import BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepLib import BRepLib
from OCP.gp import gp_Pnt, gp_Vec
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopoDS import TopoDS

from ..errors import KernelError
from .guard import check_done, kernel
from .topo import geometric_edges, shells_of, wrapped


def sew(faces, tolerance: float):
    """``BRepBuilderAPI_Sewing`` of build123d faces; returns ``(sewed TopoDS_Shape, info)``
    where ``info`` counts free and multiple edges of the result."""
    with kernel("BRepBuilderAPI_Sewing"):
        sewing = BRepBuilderAPI_Sewing(tolerance)
        for f in faces:
            sewing.Add(wrapped(f))
        sewing.Perform()
        shape = sewing.SewedShape()
        info = {
            "free_edges": sewing.NbFreeEdges(),
            "multiple_edges": sewing.NbMultipleEdges(),
            "degenerated_shapes": sewing.NbDegeneratedShapes(),
        }
    return shape, info


def shell(faces, tolerance: float):
    """One build123d ``Shell`` sewn from ``faces`` (KernelError if they do not form one)."""
    import build123d as bd

    shape, info = sew(faces, tolerance)
    shells = shells_of(shape)
    if len(shells) != 1:
        raise KernelError(f"BRepBuilderAPI_Sewing: the patches form {len(shells)} shells, expected 1")
    return bd.Shell(shells[0]), info


def solid(faces, tolerance: float):
    """A closed, outward-oriented build123d ``Solid`` sewn from ``faces``."""
    import build123d as bd

    sh, info = shell(faces, tolerance)
    if info["free_edges"]:
        raise KernelError(f"BRepBuilderAPI_Sewing: {info['free_edges']} free edges left, the shell is not closed")
    with kernel("BRepBuilderAPI_MakeSolid"):
        maker = BRepBuilderAPI_MakeSolid(TopoDS.Shell(sh.wrapped))
        check_done(maker, "BRepBuilderAPI_MakeSolid")
        s = maker.Solid()
        BRepLib.OrientClosedSolid_s(s)
        valid = BRepCheck_Analyzer(s).IsValid()
    if not valid:
        raise KernelError("BRepCheck_Analyzer: the sewn limit-surface solid is not valid")
    return bd.Solid(s), info


def shared_edge_samples(shape, samples: int = 17) -> list[tuple]:
    """OCCT's own view of how the faces of a sewn shape meet: for every non-degenerate
    edge shared by two faces, ``(points, normals)``, each a pair of ``(samples, 3)``
    arrays: the two faces' surface points at ``samples`` points of the edge (through each
    face's p-curve) and their outward normals (face orientation applied, not unit).  A
    per-edge loop (a check, not an evaluation path)."""
    s = wrapped(shape)
    out = []
    with kernel("edge continuity (BRepAdaptor_Curve2d)"):
        for _, edge, faces in geometric_edges(s):
            if len(faces) != 2:
                continue
            pts, nrm = [], []
            for face in faces:
                pcurve = BRepAdaptor_Curve2d(edge, face)
                t0, t1 = pcurve.FirstParameter(), pcurve.LastParameter()
                surf = BRepAdaptor_Surface(face, False)
                sign = -1.0 if face.Orientation() == TopAbs_REVERSED else 1.0
                p_f, n_f = [], []
                for t in np.linspace(t0, t1, samples):
                    uv = pcurve.Value(float(t))
                    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
                    surf.D1(uv.X(), uv.Y(), p, du, dv)
                    n = du.Crossed(dv)
                    p_f.append((p.X(), p.Y(), p.Z()))
                    n_f.append((sign * n.X(), sign * n.Y(), sign * n.Z()))
                pts.append(np.array(p_f))
                nrm.append(np.array(n_f))
            out.append((pts, nrm))
    return out
