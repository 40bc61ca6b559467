"""Full-precision serialization of OCCT models.

OCCT's writers print reals with 12 (STEP) or 10 (IGES) significant digits by default,
which moves a NURBS pole by up to ~5e-13 (STEP) or ~5e-10 (IGES) relative.  Writing
with ``%.16E`` (17 significant digits) makes every double survive the text round trip
bit for bit (IEEE 754: 17 digits identify a double uniquely).
"""

from __future__ import annotations

import io

from ..errors import KernelError
from .guard import kernel
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.StepData import StepData_StepWriter

#: printf format of reals: 17 significant digits, the round-trip precision of a double
FLOAT_FORMAT = "%.16E"


def write_bytes(path: str, data: bytes) -> None:
    with open(path, "wb") as fh:
        fh.write(data)


def step_text(shape) -> bytes:
    """AP214 STEP of a TopoDS shape with full-precision reals (``StepData_StepWriter``)."""
    with kernel("StepData_StepWriter"):
        writer = STEPControl_Writer()
        Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
        Interface_Static.SetCVal_s("write.step.unit", "MM")
        # The file's UNCERTAINTY is the precision OCCT's reader heals with.  The default,
        # the average tolerance of the shape, made the reader re-project p-curves and move
        # the re-read solids of 15 of the 41 corpus files by 4e-10 .. 6e-3 (volume or
        # centroid, relative); the greatest tolerance (mode 1) leaves 11 of them bit-exact
        # (tests/test_step_roundtrip.py holds the four it does not).
        Interface_Static.SetIVal_s("write.precision.mode", 1)
        if writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone:
            raise KernelError("STEPControl_Writer: transfer failed")
        text = StepData_StepWriter(writer.Model())
        text.FloatWriter().SetFormat(FLOAT_FORMAT, True)
        text.SendModel(writer.WS().Protocol())
        out = io.BytesIO()
        if not text.Print(out):
            raise KernelError("StepData_StepWriter: could not print the model")
    return out.getvalue()


def write_step_full(shape, path: str) -> None:
    """:func:`step_text` written to ``path`` (the caller makes this atomic)."""
    write_bytes(path, step_text(shape))
