"""STEP read/write and OCCT's own triangulation (BRepMesh) of shapes."""

from __future__ import annotations

import numpy as np

from ..errors import KernelError, SurfmodError
from .arrays import xyz
from .guard import kernel


def _quiet_messages() -> None:
    """OCCT's STEP translator prints statistics banners to stdout; keep only failures."""
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


_quiet_messages()


def compound(shapes):
    """One TopoDS_Compound of the given TopoDS shapes."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    builder = BRep_Builder()
    comp = TopoDS_Compound()
    builder.MakeCompound(comp)
    for shape in shapes:
        builder.Add(comp, shape)
    return comp


def write_step(shape, path: str) -> None:
    """Write a TopoDS shape as AP214 STEP to ``path`` (the caller makes this atomic)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    with kernel("STEPControl_Writer"):
        writer = STEPControl_Writer()
        Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
        Interface_Static.SetCVal_s("write.step.unit", "MM")
        if writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone:
            raise KernelError("STEPControl_Writer: transfer failed")
        if writer.Write(str(path)) != IFSelect_RetDone:
            raise KernelError(f"STEPControl_Writer: could not write {path}")


def read_step(path: str):
    """Read a STEP file into one TopoDS shape; unreadable files raise ``SurfmodError``."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    with kernel("STEPControl_Reader"):
        reader = STEPControl_Reader()
        status = reader.ReadFile(str(path))
        if status != IFSelect_RetDone:
            raise SurfmodError(f"path: {path} is not a readable STEP file")
        reader.TransferRoots()
        shape = reader.OneShape()
    if shape is None or shape.IsNull():
        raise SurfmodError(f"path: {path} contains no shape")
    return shape


def triangulate(shape, tolerance: float, angular: float = 0.5):
    """BRepMesh triangulation as ``(vertices, triangles)`` with vertices shared along
    face boundaries (BRepMesh discretizes each edge once), outward-oriented."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_REVERSED
    from OCP.TopLoc import TopLoc_Location

    from .topo import faces_of

    with kernel("BRepMesh_IncrementalMesh"):
        BRepMesh_IncrementalMesh(shape, float(tolerance), False, float(angular), True)
        verts, tris, offset = [], [], 0
        for face in faces_of(shape):
            loc = TopLoc_Location()
            tri = BRep_Tool.Triangulation_s(face, loc)
            if tri is None:
                continue
            trsf = loc.Transformation()
            nodes = np.array([xyz(tri.Node(i).Transformed(trsf)) for i in range(1, tri.NbNodes() + 1)])
            idx = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)], dtype=np.int64) - 1
            if face.Orientation() == TopAbs_REVERSED:
                idx = idx[:, ::-1]
            verts.append(nodes)
            tris.append(idx + offset)
            offset += len(nodes)
    if not verts:
        raise SurfmodError("shape: has no faces to triangulate")
    return weld(np.concatenate(verts), np.concatenate(tris))


def weld(vertices: np.ndarray, triangles: np.ndarray):
    """Merge vertices with identical coordinates (BRepMesh repeats shared edge nodes in
    every face's triangulation, bit-identical) and drop triangles that collapse."""
    unique, inverse = np.unique(vertices, axis=0, return_inverse=True)
    tri = inverse.reshape(-1)[triangles]
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return unique, tri[keep]
