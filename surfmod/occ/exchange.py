"""STEP read/write of TopoDS shapes (in process; files from users go through
:mod:`surfmod.occ.isolated`, which runs :func:`read_step` in a child process)."""

from __future__ import annotations

# loaded at import: the module silences OCCT's STEP banners once, on import
from OCP.Message import Message, Message_Gravity

from ..errors import SurfmodError
from .fullprecision import write_step_full
from .guard import kernel
from OCP.BRep import BRep_Builder
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopoDS import TopoDS_Compound


def _quiet_messages() -> None:
    """OCCT's STEP translator prints statistics banners to stdout; keep only failures."""
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


_quiet_messages()


def compound(shapes):
    """One TopoDS_Compound of the given TopoDS shapes."""
    builder = BRep_Builder()
    comp = TopoDS_Compound()
    builder.MakeCompound(comp)
    for shape in shapes:
        builder.Add(comp, shape)
    return comp


def write_step(shape, path: str) -> None:
    """Write a TopoDS shape as AP214 STEP to ``path`` (the caller makes this atomic), reals
    with 17 significant digits so every pole and weight survives the text bit for bit
    (OCCT's default 12 digits move poles by up to ~5e-13 relative)."""
    write_step_full(shape, path)


def read_with(reader, kind: str, path: str):
    """One TopoDS shape from ``path`` through an OCCT ``XSControl_Reader`` subclass
    instance (STEP, IGES); unreadable files raise ``SurfmodError`` naming ``kind``."""
    with kernel(f"{type(reader).__name__}"):
        if reader.ReadFile(str(path)) != IFSelect_RetDone:
            raise SurfmodError(f"path: {path} is not a readable {kind} file")
        reader.TransferRoots()
        shape = reader.OneShape()
    if shape is None or shape.IsNull():
        raise SurfmodError(f"path: {path} contains no shape")
    return shape


def read_step(path: str):
    """Read a STEP file into one TopoDS shape; unreadable files raise ``SurfmodError``."""
    return read_with(STEPControl_Reader(), "STEP", path)
