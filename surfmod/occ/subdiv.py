"""Sewing subdivision-limit patches into a shell and a solid (OCCT side of surfmod.subdiv)."""

from __future__ import annotations

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.TopAbs import TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from ..errors import KernelError
from .guard import check_done, kernel
from .topo import wrapped


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


def shells_of(shape):
    out = []
    explorer = TopExp_Explorer(shape, TopAbs_SHELL)
    while explorer.More():
        out.append(TopoDS.Shell_s(explorer.Current()))
        explorer.Next()
    return out


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
        maker = BRepBuilderAPI_MakeSolid(TopoDS.Shell_s(sh.wrapped))
        check_done(maker, "BRepBuilderAPI_MakeSolid")
        s = maker.Solid()
        BRepLib.OrientClosedSolid_s(s)
        valid = BRepCheck_Analyzer(s).IsValid()
    if not valid:
        raise KernelError("BRepCheck_Analyzer: the sewn limit-surface solid is not valid")
    return bd.Solid(s), info
