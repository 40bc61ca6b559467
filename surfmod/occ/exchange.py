"""STEP read/write of shapes (BRepMesh triangulation lives in :mod:`surfmod.occ.mesh`)."""

from __future__ import annotations

from ..errors import KernelError, SurfmodError
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
