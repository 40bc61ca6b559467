"""Open shells made from real parts: a corpus solid with faces taken out, written to STEP.

The corpus holds only closed solids, yet users bring surface models with holes (a face
not exported, a patch left out).  ``open_shell_step`` takes the largest solid of a corpus
file, drops some of its faces and writes the rest as one shell (the faces keep sharing
their edges, so the shell is open exactly along the dropped faces' boundaries).
"""

from __future__ import annotations

from pathlib import Path

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Shell

from surfmod.inputs import to_shape


def _explore(shape, kind):
    out, explorer = [], TopExp_Explorer(shape, kind)
    while explorer.More():
        out.append(explorer.Current())
        explorer.Next()
    return out


def _volume(solid) -> float:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, props)
    return abs(props.Mass())


def _area(face) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return props.Mass()


def open_shell(source, drop: int = 1):
    """The largest solid of ``source`` (a STEP path) as an open shell without its
    ``drop`` largest faces."""
    shape = to_shape(source)
    solids = _explore(shape, TopAbs_SOLID)
    solid = max(solids, key=_volume) if solids else shape
    faces = _explore(solid, TopAbs_FACE)
    keep = sorted(range(len(faces)), key=lambda i: _area(faces[i]))[: len(faces) - drop]
    shell, builder = TopoDS_Shell(), BRep_Builder()
    builder.MakeShell(shell)
    for i in sorted(keep):
        builder.Add(shell, faces[i])
    assert not BRep_Tool.IsClosed_s(shell)
    return shell


def open_shell_step(source, folder, drop: int = 1) -> Path:
    """Write :func:`open_shell` of ``source`` to ``folder/<name>_open.step``."""
    path = Path(folder) / f"{Path(source).stem}_open.step"
    writer = STEPControl_Writer()
    writer.Transfer(open_shell(source, drop), STEPControl_AsIs)
    assert writer.Write(str(path)) == IFSelect_RetDone
    return path
