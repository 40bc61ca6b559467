"""``sm.export_step`` writes the shape it was given: import -> export_step -> import keeps
every solid's volume, centroid and face count (1e-12 relative, BRepGProp's fixed Gauss
rule, which gives the same digits for the same geometry) on every corpus file.

What changed the shape, and what surfmod does about it:

- a solid whose only shell OCCT's reader uses REVERSED (it orients a closed shell by
  classifying a point at infinity, ``ShapeFix_Solid``) was written with the flag dropped
  (STEP's CLOSED_SHELL has no orientation) and came back inside out, volume negated
  (stepcode_HEAD_BACK.stp).  The writer now writes such a shell's faces reversed, and
  the reader orients every solid by the sign of its volume (``outward_solids``), since
  the classification answers IN on that part whichever way its faces point.
- OCCT's writer wrote the file's UNCERTAINTY as the average tolerance of the shape, and
  the reader heals with that precision: on 15 files it re-projected p-curves and moved
  solids by 4e-10 .. 6e-3.  The writer now gives the greatest tolerance
  (``write.precision.mode`` 1), and 11 of the 15 come back bit-exact.
- on the files of ``OCCT_REBUILDS`` OCCT's reader still gives the re-read solid other
  edges than the first read (OCCT 7.9): the difference stays with p-curves written or
  not (``write.surfacecurve.mode``), with the reader told to prefer them
  (``read.surfacecurve.mode`` ±2, ±3), with other uncertainties (1e-3 .. 1e-1, the
  file's own) and with ShapeFix's same-parameter, edge and vertex fixes off.  Those are
  OCCT's, pinned per file with the deviation measured, so a change either way shows,
  and ``export_step`` says so in a ``RoundTripWarning`` naming the solids (checked).
- edge and vertex tolerances are not STEP data: the reader derives them again (they
  come back different on most files, the geometry above bit-exact).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CORPUS
from test_occt_quirks import quirk_holds

import surfmod as sm
from surfmod.occ.step import map_solids, outward_solids
from surfmod.occ.properties import solid_figures
from surfmod.occ.topo import faces_of, loose_faces, solids_of

#: file -> (largest relative change of a solid's volume or centroid, or of a loose face's area or
#: centroid, measured; the reason)
OCCT_REBUILDS = {
    "ansys_race_car_nose.stp": (1.6e-05, "measured 1.21e-05 (area of loose face 108 of 141; three more "
                                         "2.6e-7 .. 3.6e-10): Parasolid B-spline faces with crowded knots"),
    "axom_boxed_sphere.step": (1.6e-05, "measured 1.22e-05: Rhino B-spline faces, 2 solids (was 5.75e-3 at the "
                                        "average uncertainty)"),
    "nist_ftc_07_asme1_rd.stp": (1.6e-09, "measured 1.23e-09: B-spline faces (was 3.34e-7)"),
    "nist_ftc_10_asme1_rb.stp": (2.2e-09, "measured 1.68e-09: tori, one B-spline (was 6.3e-8)"),
    "occt_cornetta.stp": (1.6e-07, "measured 1.27e-07 (volume; centroid 6.6e-8): ST-Developer B-spline faces, "
                                   "60 of 254 edges 1e-4 to 9.2e-3 off their p-curves' images"),
    "pythonocc_Ventilator.stp": (1.0e-06, "measured 7.87e-07: edges up to 1.4e-2 off their extrusion faces "
                                          "(was 1.04e-6)"),
}
#: files of OCCT_REBUILDS that OCCT 8.0 writes and reads back exactly (change 0.0)
REBUILT_BY_OCCT_79_ONLY = {"axom_boxed_sphere.step"}


def roundtrip_change(path, tmp_path, *, warns: bool = False) -> float:
    """Largest relative change of a solid's volume or centroid (to volume^(1/3)) through
    ``export_step``; solid and face counts must not change.  ``export_step`` must warn
    (naming a solid) exactly when ``warns``."""
    import warnings

    first = sm.import_step(path)
    out = tmp_path / "again.step"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", sm.RoundTripWarning)
        sm.export_step(first, out)
    said = [str(w.message) for w in caught if issubclass(w.category, sm.RoundTripWarning)]
    assert bool(said) == warns, (path.name, said)
    assert all("relative change" in m for m in said), said
    again = sm.import_step(out)
    a, b = solids_of(first.wrapped), solids_of(again.wrapped)
    assert len(a) == len(b), (path.name, "solids", len(a), len(b))
    assert len(faces_of(first)) == len(faces_of(again)), (path.name, "faces")
    worst = 0.0
    for i, (x, y) in enumerate(zip(a, b)):
        assert len(faces_of(x)) == len(faces_of(y)), (path.name, i, "faces")
        (va, ca), (vb, cb) = solid_figures(x), solid_figures(y)
        assert va > 0 and vb > 0, (path.name, i, "inside out", va, vb)
        worst = max(worst, abs(va - vb) / va, float(np.abs(ca - cb).max()) / va ** (1 / 3))
    for x, y in zip(loose_faces(first.wrapped), loose_faces(again.wrapped), strict=True):
        (sa, ca), (sb, cb) = solid_figures(x), solid_figures(y)
        worst = max(worst, abs(sa - sb) / sa, float(np.abs(ca - cb).max()) / sa ** 0.5)
    return worst


def test_reversed_shell_part_round_trips_outward(tmp_path):
    """stepcode_HEAD_BACK.stp: read outward, written, read again: the same solid, not its
    inside-out twin."""
    assert roundtrip_change(CORPUS / "stepcode_HEAD_BACK.stp", tmp_path) <= 1e-12


def test_outward_solids_reverses_inside_out_solids_only():
    import build123d as bd

    box = bd.Solid.make_box(1, 2, 3).wrapped
    moved = bd.Solid.make_box(1, 1, 1).moved(bd.Location((5, 0, 0))).wrapped
    comp = bd.Compound([bd.Solid(box.Reversed()), bd.Solid(moved)]).wrapped
    fixed = outward_solids(comp)
    vols = sorted(solid_figures(s)[0] for s in solids_of(fixed))
    assert vols == pytest.approx([1.0, 6.0], rel=1e-14)
    centres = np.array(sorted(tuple(solid_figures(s)[1]) for s in solids_of(fixed)))
    np.testing.assert_allclose(centres, [(0.5, 1.0, 1.5), (5.5, 0.5, 0.5)], atol=1e-14)  # locations kept
    assert outward_solids(box) is box  # nothing to change: the same shape
    assert solid_figures(outward_solids(box.Reversed()))[0] == pytest.approx(6.0, rel=1e-14)


def test_map_solids_keeps_what_it_does_not_replace():
    import build123d as bd

    face = bd.Face.make_rect(1, 1).wrapped
    assert map_solids(face, lambda s: s.Reversed()) is face
    comp = bd.Compound([bd.Solid.make_box(1, 1, 1), bd.Face.make_rect(2, 2)]).wrapped
    out = map_solids(comp, lambda s: s.Reversed())
    assert len(faces_of(out)) == 7 and solid_figures(solids_of(out)[0])[0] == pytest.approx(-1.0)


@pytest.mark.corpus
def test_export_step_round_trip_keeps_every_solid(corpus_file, tmp_path):
    rebuilt = corpus_file.name in OCCT_REBUILDS
    if corpus_file.name in REBUILT_BY_OCCT_79_ONLY:  # OCCT 8.0's reader gives it back bit-exact
        rebuilt = quirk_holds("test_step_roundtrip.py::test_export_step_round_trip_keeps_every_solid")
    change = roundtrip_change(corpus_file, tmp_path, warns=rebuilt)
    if rebuilt:
        bound, _ = OCCT_REBUILDS[corpus_file.name]
        assert 1e-12 < change <= bound, f"{corpus_file.name}: {change:.3g} (pinned {bound:.3g}): update OCCT_REBUILDS"
    else:
        assert change <= 1e-12, f"{corpus_file.name}: the round trip changes a solid by {change:.3g}"


def _open_shell_solid():
    """A solid whose one shell is a box without its top: not closed."""
    import build123d as bd
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Shell, TopoDS_Solid

    builder, shell, solid = BRep_Builder(), TopoDS_Shell(), TopoDS_Solid()
    builder.MakeShell(shell)
    for face in faces_of(bd.Solid.make_box(1, 2, 3).wrapped)[:5]:
        builder.Add(shell, face)
    builder.MakeSolid(solid)
    builder.Add(solid, shell)
    return solid


def test_export_step_names_a_solid_the_file_cannot_hold(tmp_path):
    # STEP's MANIFOLD_SOLID_BREP needs a closed shell: OCCT writes an open one as a
    # surface model and reads it back as a shell, so the solid is lost: said, or refused
    out = tmp_path / "open.step"
    with pytest.warns(sm.RoundTripWarning, match=r"solids: 1 -> 0; faces in no solid: 0 -> 5"):
        sm.export_step(_open_shell_solid(), out)
    assert len(faces_of(sm.import_step(out))) == 5  # written all the same, every face in it
    refused = tmp_path / "refused.step"
    with pytest.raises(sm.SurfmodError, match=r"^objects: refused.step read back differs .*solids: 1 -> 0"):
        sm.export_step(_open_shell_solid(), refused, strict=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["open.step"]  # nothing written, no litter


def test_export_step_says_an_inside_out_solid_comes_back_outward(tmp_path):
    import build123d as bd

    box = bd.Solid.make_box(1, 2, 3).wrapped.Reversed()
    with pytest.warns(sm.RoundTripWarning, match=r"solid 1: enclosed volume -6 -> 6 \(turned outward\)"):
        sm.export_step(box, tmp_path / "box.step")


def test_export_step_keeps_loose_b_spline_faces_and_is_silent(tmp_path):
    # a surface model of loose faces: every face back, none in a solid, bit-exact areas
    import warnings

    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from surfmod.occ.topo import compound

    def area(face):
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        return props.Mass()

    faces = faces_of(sm.import_step(CORPUS / "stepcode_MAINBODY_BACK.stp"))
    out = tmp_path / "loose.step"
    with warnings.catch_warnings():
        warnings.simplefilter("error", sm.RoundTripWarning)
        sm.export_step(compound(faces), out)
    again = faces_of(sm.import_step(out))
    assert len(again) == len(faces) == 31 and not solids_of(sm.import_step(out).wrapped)
    np.testing.assert_allclose([area(f) for f in again], [area(f) for f in faces], rtol=1e-12)


@pytest.mark.parametrize("direct", [True, False])
def test_a_spindle_torus_is_written_on_its_exact_revolution(tmp_path, direct):
    """A torus whose major radius is below its minor (fillets of SolidWorks parts) is written
    as a revolution of its exact meridian circle with the same (u, v): OCCT's writer alone
    makes it a revolution of a B-spline 5.5e-7 off (a solid of such faces came back with
    another volume and `surfmod convert` refused it)."""
    import build123d as bd
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepTools import BRepTools
    from OCP.Geom import Geom_ToroidalSurface
    from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
    from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt
    from OCP.TopoDS import TopoDS
    from surfmod.occ.step import exact_spindle_tori

    frame = gp_Ax3(gp_Pnt(1, 2, 3), gp_Dir(0.3, 0.2, 1), gp_Dir(1, 0, -0.3))
    if not direct:
        frame.YReverse()
    torus = Geom_ToroidalSurface(frame, 0.3, 1.2)
    face = BRepBuilderAPI_MakeFace(torus, np.pi, 1.5 * np.pi, 0.0, 0.5 * np.pi, 1e-7).Face()
    exact = BRep_Tool.Surface_s(TopoDS.Face(exact_spindle_tori(face)))
    grid = [(u, v) for u in np.linspace(0, 6, 7) for v in np.linspace(0, 6, 7)]
    assert max(exact.Value(u, v).Distance(torus.Value(u, v)) for u, v in grid) < 1e-14
    path = tmp_path / "spindle.step"
    sm.export_step(bd.Face(face), path, strict=True)
    back = TopoDS.Face(sm.import_step(path).faces()[0].wrapped)
    surface = BRep_Tool.Surface_s(back)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(back)
    far = max(GeomAPI_ProjectPointOnSurf(surface.Value(u, v), torus).LowerDistance()
              for u in np.linspace(u0, u1, 9) for v in np.linspace(v0, v1, 9))
    assert far < 1e-12  # 5.5e-7 as OCCT writes it


def test_shape_changes_measures_every_face_in_no_solid(tmp_path):
    """A loose face whose surface the writer moves (OCCT's own writer, a spindle torus: 5.5e-7
    off) is named with its area and centroid; solids alone were measured before."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_ToroidalSurface
    from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt
    from surfmod.io.step_iges import shape_changes
    from surfmod.occ.step import step_text, write_bytes

    torus = Geom_ToroidalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 0.3, 1.2)
    face = BRepBuilderAPI_MakeFace(torus, np.pi, 1.5 * np.pi, 0.0, 0.5 * np.pi, 1e-7).Face()
    write_bytes(tmp_path / "raw.step", step_text(face))  # the writer alone, no exact revolution
    said = shape_changes(face, sm.import_step(tmp_path / "raw.step").wrapped)
    assert len(said) == 1 and said[0].startswith("face 1 in no solid: area 3.15021 -> 3.15021 (relative change 2.1e-07)")
    assert shape_changes(face, face) == []
