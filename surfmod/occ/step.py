"""STEP read/write of TopoDS shapes (``STEPControl``), with full-precision reals, and OCCT's
native BREP format (``BRepTools`` files for gmsh, ``BinTools`` bytes between processes).

In process; users' files go through :func:`surfmod.inputs.read_step_file` (a child process).
The public ``import_step``/``export_step`` over this module are :mod:`surfmod.io.step_iges`'s.

OCCT's writers print reals with 12 (STEP) or 10 (IGES) significant digits by default,
which moves a NURBS pole by up to ~5e-13 (STEP) or ~5e-10 (IGES) relative.  Writing
with ``%.16E`` (17 significant digits) makes every double survive the text round trip
bit for bit (IEEE 754: 17 digits identify a double uniquely).
"""

from __future__ import annotations

import io

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.BRepTools import BRepTools
from OCP.BinTools import BinTools
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.Message import Message, Message_Gravity
from OCP.Geom import Geom_Circle, Geom_SurfaceOfRevolution, Geom_ToroidalSurface
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Reader, STEPControl_Writer
from OCP.StepData import StepData_StepWriter
from OCP.TopAbs import (TopAbs_COMPOUND, TopAbs_COMPSOLID, TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED,
                        TopAbs_SHELL, TopAbs_SOLID)
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import (TopoDS, TopoDS_Compound, TopoDS_CompSolid, TopoDS_Iterator, TopoDS_Shape, TopoDS_Shell,
                        TopoDS_Solid)
from OCP.gp import gp_Ax1, gp_Ax2, gp_Pnt

from ..errors import KernelError, SurfmodError
from .guard import kernel
from .properties import solid_figures
from .topo import explore


# OCCT's STEP translator prints statistics banners to stdout: only failures are kept
for _printer in Message.DefaultMessenger_s().Printers():
    _printer.SetTraceLevel(Message_Gravity.Message_Fail)


def _solid_shells_forward(solid):
    """``solid`` (as stored) with each REVERSED shell replaced by :func:`_forward_shell`,
    or ``solid`` itself when none is reversed."""
    children, changed = [], False
    it = TopoDS_Iterator(solid, False, False)  # the shells as the solid holds them
    while it.More():
        child = it.Value()
        if child.ShapeType() == TopAbs_SHELL and child.Orientation() == TopAbs_REVERSED:
            child, changed = _forward_shell(child), True
        children.append(child)
        it.Next()
    if not changed:
        return solid
    builder = BRep_Builder()
    out = TopoDS_Solid()
    builder.MakeSolid(out)
    for child in children:
        builder.Add(out, child)
    out.Location(solid.Location())
    out.Orientation(solid.Orientation())
    return out


def _forward_shell(shell):
    """The same faces in a FORWARD shell: each face's orientation composed with the
    shell's (and its location with the shell's), so the faces face the same way."""
    builder = BRep_Builder()
    out = TopoDS_Shell()
    builder.MakeShell(out)
    it = TopoDS_Iterator(shell, True, True)  # faces with the shell's orientation and location applied
    while it.More():
        builder.Add(out, it.Value())
        it.Next()
    out.Closed(shell.Closed())
    return out


def map_solids(shape, fn):
    """``shape`` with each solid ``s`` in it replaced by ``fn(s)`` (``fn`` returns ``s``
    itself to keep it); compounds that hold a replaced solid are rebuilt with their own
    location and orientation, everything else is shared.  ``shape`` itself when nothing
    changes."""
    kind = shape.ShapeType()
    if kind == TopAbs_SOLID:
        return fn(shape)
    if kind not in (TopAbs_COMPOUND, TopAbs_COMPSOLID):
        return shape
    children, changed = [], False
    it = TopoDS_Iterator(shape, False, False)  # children as stored, relative to ``shape``
    while it.More():
        child = map_solids(it.Value(), fn)
        changed |= not child.IsSame(it.Value()) or child.Orientation() != it.Value().Orientation()
        children.append(child)
        it.Next()
    if not changed:
        return shape
    builder = BRep_Builder()
    out = TopoDS_Compound() if kind == TopAbs_COMPOUND else TopoDS_CompSolid()
    (builder.MakeCompound if kind == TopAbs_COMPOUND else builder.MakeCompSolid)(out)
    for child in children:
        builder.Add(out, child)
    out.Location(shape.Location())
    out.Orientation(shape.Orientation())
    return out


def write_step(shape, path: str) -> None:
    """Write a TopoDS shape as AP214 STEP (:func:`step_text`) to ``path`` (the caller makes
    this atomic).

    A solid whose shell is used REVERSED (OCCT's reader makes one of a file's inside-out
    closed shell) is written as a FORWARD shell of its faces reversed: the same solid, and
    the file holds every face the way it faces, for any reader (a STEP CLOSED_SHELL has
    no orientation of its own).  Faces on a spindle torus are written on its exact
    revolution (:func:`exact_spindle_tori`)."""
    write_bytes(path, step_text(map_solids(exact_spindle_tori(shape), _solid_shells_forward)))


def _spindle(face):
    """``(torus, location)`` of a face on a torus whose major radius is below its minor, or None."""
    location = TopLoc_Location()
    surface = BRep_Tool.Surface_s(face, location)
    spindle = isinstance(surface, Geom_ToroidalSurface) and surface.MajorRadius() < surface.MinorRadius()
    return (surface, location) if spindle else None


def exact_spindle_tori(shape):
    """A copy of ``shape`` whose faces on a spindle torus (as some writers' fillets) lie on
    the same surface, same (u, v), as a revolution of its exact meridian circle: OCCT's STEP
    writer makes it a revolution of a B-spline 5e-7 off.  ``shape`` itself when it has none."""
    if not any(_spindle(TopoDS.Face(f)) for f in explore(shape, TopAbs_FACE)):
        return shape
    shape, builder = BRepBuilderAPI_Copy(shape, True, False).Shape(), BRep_Builder()
    for face in (TopoDS.Face(f.Oriented(TopAbs_FORWARD)) for f in explore(shape, TopAbs_FACE)):
        if (found := _spindle(face)) is None:
            continue
        (torus, location), frame = found, found[0].Position()
        x, z, origin = frame.XDirection(), frame.Direction(), frame.Location()
        centre = gp_Pnt(origin.XYZ().Added(x.XYZ().Multiplied(torus.MajorRadius())))
        meridian = Geom_Circle(gp_Ax2(centre, x.Crossed(z), x), torus.MinorRadius())  # at v: cos v x + sin v z
        exact = Geom_SurfaceOfRevolution(meridian, gp_Ax1(origin, z if frame.Direct() else z.Reversed()))
        edges = [TopoDS.Edge(e) for e in explore(face, TopAbs_EDGE)]
        sides = [(TopAbs_FORWARD, TopAbs_REVERSED) if BRep_Tool.IsClosed_s(e, face) else (TopAbs_FORWARD,) for e in edges]
        pcurves = [[BRep_Tool.CurveOnSurface_s(TopoDS.Edge(e.Oriented(o)), face, 0.0, 0.0) for o in s]
                   for e, s in zip(edges, sides)]  # keyed by the face's surface: read before it changes
        builder.UpdateFace(face, exact, location, BRep_Tool.Tolerance_s(face))
        for edge, curves in zip(edges, pcurves):
            builder.UpdateEdge(edge, *curves, exact, location, BRep_Tool.Tolerance_s(edge))
    return shape


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


def outward_solids(shape, inside_out: list | None = None):
    """``shape`` with every solid whose enclosed volume is negative (its faces point
    inwards) reversed, so each solid's faces point out of its material.

    OCCT's reader orients a closed shell by classifying a point at infinity
    (``ShapeFix_Solid``), which on some valid parts (stepcode_HEAD_BACK.stp) answers IN
    whatever the faces say; the sign of the volume over the faces as oriented decides instead.

    ``inside_out``, a list, receives ``(number, volume)`` of each solid of a freshly
    read ``shape`` that is inside out *in the file* (numbered from 1 in explorer order),
    with its enclosed volume as the file has it: STEP's closed shell has no orientation,
    the reader builds it FORWARD as the file's faces point and may use it REVERSED, so
    the file's orientation is the volume's sign with a REVERSED shell counted FORWARD.
    """
    met = [0]

    def outward(solid):
        met[0] += 1
        volume = solid_figures(solid)[0]
        # a REVERSED shell, which :func:`_solid_shells_forward` would turn, counted FORWARD
        in_file = volume * (-1.0 if _solid_shells_forward(solid) is not solid else 1.0)
        if inside_out is not None and in_file < 0.0:
            inside_out.append((met[0], in_file))
        return solid.Reversed() if volume < 0.0 else solid

    with kernel("BRepGProp.VolumeProperties_s"):
        return map_solids(shape, outward)


def read_step(path: str, inside_out: list | None = None):
    """Read a STEP file into one TopoDS shape, its solids :func:`outward_solids` (those
    inside out in the file added to ``inside_out``); unreadable files raise
    ``SurfmodError``."""
    return outward_solids(read_with(STEPControl_Reader(), "STEP", path), inside_out)


def write_brep(shape, path) -> None:
    """``shape`` as an OCCT native BREP file at ``path`` (what gmsh reads without a STEP
    translation of its own)."""
    with kernel("BRepTools.Write_s"):
        if not BRepTools.Write_s(shape, str(path)):
            raise SurfmodError(f"path: could not write BREP {path}")


def read_brep(path):
    """The shape of an OCCT native BREP file at ``path`` (as :func:`write_brep` writes
    it: every tolerance, orientation and p-curve as in memory, nothing healed); a file
    that is not one raises ``SurfmodError`` naming it."""
    shape = TopoDS_Shape()
    with kernel("BRepTools.Read_s"):
        ok = BRepTools.Read_s(shape, str(path), BRep_Builder())
    if not ok or shape.IsNull():
        raise SurfmodError(f"path: {path} is not a readable BREP file")
    return shape


def brep_bytes(shape) -> bytes:
    """``shape`` as OCCT binary BREP bytes (``BinTools``): how a shape crosses to another
    process, every number bit for bit."""
    with kernel("BinTools.Write"):
        out = io.BytesIO()
        BinTools.Write_s(shape, out)
    return out.getvalue()


def brep_from_bytes(data: bytes):
    """The shape of :func:`brep_bytes`."""
    with kernel("BinTools.Read"):
        shape = TopoDS_Shape()
        BinTools.Read_s(shape, io.BytesIO(data))
    return shape


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
        # The file's UNCERTAINTY is the precision OCCT's reader heals with: the default (the
        # shape's average tolerance) made it re-project p-curves and move re-read solids by up
        # to 6e-3 relative; the greatest (mode 1) does not (tests/test_step_roundtrip.py).
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
