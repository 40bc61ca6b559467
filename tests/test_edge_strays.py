"""Edges whose p-curves stray from their 3-D curves beyond the declared tolerance: measured
independently of BRepCheck (:mod:`surfmod.readback.strays`), reported per face by ``surfmod
check`` and named by ``surfmod mass`` (exit 3, ambiguous model)."""

from __future__ import annotations

import dataclasses

import build123d as bd
import numpy as np
import pytest
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.gp import gp_Vec2d
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from surfmod.occ.bindings import TopTools_IndexedMapOfShape

import surfmod as sm
from surfmod.cli import main
from surfmod.cli.check import _stray_notes
from surfmod.readback.strays import edge_strays

SHIFT = 0.05


def _displaced(shift=SHIFT):
    """A 10 x 20 x 30 box whose first face has the p-curve of its first edge moved by
    ``shift`` across the face (the 3-D edge and the other face stay): ``(solid, edge, face)``."""
    solid = BRepBuilderAPI_Copy(bd.Box(10, 20, 30).wrapped).Shape()
    faces, edges = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(solid, TopAbs_FACE, faces)
    TopExp.MapShapes_s(solid, TopAbs_EDGE, edges)
    face = TopoDS.Face(faces.FindKey(1))
    edge = TopoDS.Edge(_first_edge(face))
    c2d = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 1.0)
    moved = c2d.Translated(gp_Vec2d(shift, shift))
    BRep_Builder().UpdateEdge(edge, moved, face, BRep_Tool.Tolerance_s(edge))
    return solid, edges.FindIndex(edge) - 1, 0


def _first_edge(face):
    from OCP.TopExp import TopExp_Explorer

    return TopExp_Explorer(face, TopAbs_EDGE).Current()


def test_clean_solids_have_no_strays():
    for shape in (bd.Box(1, 2, 3), bd.Cylinder(1, 2) - bd.Box(0.5, 0.5, 3), bd.Sphere(2)):
        strays = edge_strays(shape)
        assert strays and max(max(e.stray, e.gap) for e in strays) < 1e-9
        assert not any(e.ambiguous for e in strays)


def test_a_displaced_pcurve_is_measured_and_named():
    solid, edge, face = _displaced()
    strays = {e.edge: e for e in edge_strays(solid)}
    e = strays[edge]
    # moved by (d, d) in (u, v) of a plane whose parameters are lengths: the image lies d
    # across the 3-D segment and its far end d beyond the segment's end, d sqrt 2 from it
    assert e.ambiguous and face in e.faces
    assert e.stray == pytest.approx(SHIFT * np.sqrt(2), rel=1e-9)
    assert e.gap == pytest.approx(SHIFT * np.sqrt(2), rel=1e-9)  # the images on the two faces part
    assert not any(x.ambiguous for k, x in strays.items() if k != edge)
    # (a STEP file does not keep the displaced p-curve: the reader rebuilds it; the notes
    # of ``surfmod check`` come from this function on the shape read)
    notes = _stray_notes(solid)
    assert sorted(notes) == sorted(e.faces) and face in notes  # the edge's two faces, each says so
    assert all(n.startswith(f"ambiguous: 1 edge(s) whose p-curves stray beyond their tolerance, worst edge {edge}: 7.07e-02")
               for n in notes.values())


def test_mass_names_the_edges_and_exits_3(monkeypatch, tmp_path, capsys):
    import surfmod.cli.mass as mass

    solid, edge, _ = _displaced()
    path = tmp_path / "displaced.step"  # read as the displaced solid itself (STEP would rebuild it)
    sm.export_step(bd.Solid(solid), path)
    monkeypatch.setattr(mass, "to_shape", lambda *a, **k: solid)
    real = mass.mass_properties

    def centroid_off(shape, density=1.0, **kw):  # an integrator that follows the p-curve
        r = real(shape, density, **kw)
        return r if kw.get("method") == "occt" else dataclasses.replace(r, centroid=np.asarray(r.centroid) + 1e-4)

    monkeypatch.setattr(mass, "mass_properties", centroid_off)
    monkeypatch.setattr(mass, "boundary_ambiguity", lambda s: 0.0)  # only the strays explain it
    monkeypatch.setattr(mass.mass_reference, "settle", lambda *a: (None, "REFERENCE UNDECIDED: (test)"))  # nor can it tell
    assert main(["mass", str(path), "--no-progress"]) == 3
    out = capsys.readouterr().out
    assert "AMBIGUOUS MODEL: centroid differs" in out and "1 edge(s) have p-curves straying" in out
    assert f"edge {edge} of faces" in out
    assert out.count(f"edge {edge} of faces") == 2 and "NOTE: 1 edge(s) have p-curves straying" in out
    assert "the file's edges leave its volume open by up to" in out


def test_mass_exit_0_says_all_four_agree(tmp_path, capsys):
    path = tmp_path / "box.step"
    sm.export_step(bd.Box(1, 2, 3) - bd.Cylinder(0.3, 5), path)
    assert main(["mass", str(path), "--no-progress"]) == 0
    assert "AGREE: volume, area, centroid and inertia all agree with BRepGProp within 1e-07" in capsys.readouterr().out
