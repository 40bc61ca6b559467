"""IGES read/write through OCCT's ``IGESControl`` (the STEP side is ``step.py``).

Reals are written with 17 significant digits (as :mod:`surfmod.occ.step` writes them), so
B-spline poles, weights and knots come back bit for bit; OCCT's own ``Write`` prints 10.

The same concept as :mod:`surfmod.io.step_iges`, whose OCCT side (``IGESControl``) this is.
"""

from __future__ import annotations

import io

from ..errors import KernelError
from .step import FLOAT_FORMAT, read_with, write_bytes
from .guard import kernel
from OCP.IGESControl import IGESControl_Controller, IGESControl_Reader, IGESControl_Writer
from OCP.IGESData import IGESData_IGESWriter
from OCP.IGESSelect import IGESSelect_WorkLibrary
from OCP.Interface import Interface_Static


def iges_text(shape, *, brep: bool = False) -> bytes:
    """IGES 5.3 text of a TopoDS shape.  ``brep=False`` writes faces as trimmed surfaces
    (entity 144 over 128 B-splines), what most NURBS tools read; ``brep=True`` writes
    MSBO B-rep solids (entity 186)."""
    with kernel("IGESControl_Writer"):
        IGESControl_Controller.Init_s()
        Interface_Static.SetIVal_s("write.iges.brep.mode", 1 if brep else 0)
        writer = IGESControl_Writer("MM", 1 if brep else 0)
        if not writer.AddShape(shape):
            raise KernelError("IGESControl_Writer: the shape could not be translated")
        writer.ComputeModel()
        text = IGESData_IGESWriter(writer.Model())
        text.FloatWriter().SetFormat(FLOAT_FORMAT, True)
        text.SendModel(IGESSelect_WorkLibrary.DefineProtocol_s())
        out = io.BytesIO()
        if not text.Print(out):
            raise KernelError("IGESData_IGESWriter: could not print the model")
    return out.getvalue()


def write_iges(shape, path: str, *, brep: bool = False) -> None:
    """:func:`iges_text` written to ``path`` (the caller makes this atomic)."""
    write_bytes(path, iges_text(shape, brep=brep))


def read_iges(path: str):
    """Read an IGES file into one TopoDS shape; unreadable files raise ``SurfmodError``."""
    return read_with(IGESControl_Reader(), "IGES", path)
