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
- on the files of ``OCCT_REBUILDS`` OCCT's reader gives the re-read solid other edges
  than the first read (OCCT 7.9): the difference stays the same with p-curves written
  (``write.surfacecurve.mode`` 1) and with ShapeFix's same-parameter, edge and vertex
  fixes off (``FixShape.*Mode`` 0); with every fix off the re-read is not even closed.
  Those are OCCT's, pinned per file with the deviation measured, so a change either way
  shows.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CORPUS

import surfmod as sm
from surfmod.occ.step import map_solids, outward_solids
from surfmod.occ.topo import faces_of, solids_of

#: file -> (largest relative change of a solid's volume or centroid, measured; the reason)
OCCT_REBUILDS = {
    "axom_boxed_sphere.step": (0.00719, "measured 0.00575: Rhino B-spline faces, 2 solids"),
    "build123d_M6-1x12-countersunk-screw.step": (2e-08, "measured 1.6e-08: B-spline thread"),
    "koch_Follower_Gripper_Static_Part.STEP": (1.3e-08, "measured 1.04e-08: SolidWorks 2024 quintic trims; plain "
                                                        "STEPControl write and read: the same change (checked)"),
    "soarm_Motor1_holder.step": (1.91e-06, "measured 1.52e-06: Fusion 360, p-curves past a B-spline's knot range; "
                                           "plain STEPControl write and read: the same change (checked)"),
    "nist_ctc_04_asme1_rd.stp": (4.97e-10, "measured 3.98e-10: cones, tori, spheres"),
    "nist_ctc_05_asme1_rd.stp": (2.27e-07, "measured 1.82e-07: B-spline faces"),
    "nist_ftc_07_asme1_rd.stp": (4.18e-07, "measured 3.34e-07: B-spline faces; fixes off: same change (checked)"),
    "nist_ftc_10_asme1_rb.stp": (7.87e-08, "measured 6.3e-08: tori, one B-spline"),
    "occt_screw.step": (1.09e-09, "measured 8.7e-10: tori, cones; fixes off: same change (checked)"),
    "pythonocc_11752.stp": (8.58e-08, "measured 6.86e-08: 1018 faces"),
    "pythonocc_Ventilator.stp": (1.3e-06, "measured 1.04e-06: edges up to 1.4e-2 off their extrusion faces"),
    "stepcode_MAINBODY_BACK.stp": (1.61e-05, "measured 1.29e-05: CATIA B-spline faces, edge tolerance 6.4e-3; "
                                             "fixes off: same change (checked)"),
    "stepcode_MAINBODY_FRONT.stp": (1.45e-06, "measured 1.16e-06: CATIA B-spline faces"),
    "stepcode_TAIL_MIDDLE_PART.stp": (8.86e-09, "measured 7.09e-09: CATIA"),
    "stepcode_TAIL_TURBINE.stp": (1.77e-06, "measured 1.42e-06: a CATIA sphere face whose edge tolerance re-reads "
                                            "as 7.9e-4 (was 3.9e-3); fixes off: same change (checked)"),
}


def _props(solid):
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    vp = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, vp)
    c = vp.CentreOfMass()
    return vp.Mass(), np.array([c.X(), c.Y(), c.Z()])


def roundtrip_change(path, tmp_path) -> float:
    """Largest relative change of a solid's volume or centroid (to volume^(1/3)) through
    ``export_step``; solid and face counts must not change."""
    first = sm.import_step(path)
    out = tmp_path / "again.step"
    sm.export_step(first, out)
    again = sm.import_step(out)
    a, b = solids_of(first.wrapped), solids_of(again.wrapped)
    assert len(a) == len(b), (path.name, "solids", len(a), len(b))
    assert len(faces_of(first)) == len(faces_of(again)), (path.name, "faces")
    worst = 0.0
    for i, (x, y) in enumerate(zip(a, b)):
        assert len(faces_of(x)) == len(faces_of(y)), (path.name, i, "faces")
        (va, ca), (vb, cb) = _props(x), _props(y)
        assert va > 0 and vb > 0, (path.name, i, "inside out", va, vb)
        worst = max(worst, abs(va - vb) / va, float(np.abs(ca - cb).max()) / va ** (1 / 3))
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
    vols = sorted(_props(s)[0] for s in solids_of(fixed))
    assert vols == pytest.approx([1.0, 6.0], rel=1e-14)
    centres = np.array(sorted(tuple(_props(s)[1]) for s in solids_of(fixed)))
    np.testing.assert_allclose(centres, [(0.5, 1.0, 1.5), (5.5, 0.5, 0.5)], atol=1e-14)  # locations kept
    assert outward_solids(box) is box  # nothing to change: the same shape
    assert _props(outward_solids(box.Reversed()))[0] == pytest.approx(6.0, rel=1e-14)


def test_map_solids_keeps_what_it_does_not_replace():
    import build123d as bd

    face = bd.Face.make_rect(1, 1).wrapped
    assert map_solids(face, lambda s: s.Reversed()) is face
    comp = bd.Compound([bd.Solid.make_box(1, 1, 1), bd.Face.make_rect(2, 2)]).wrapped
    out = map_solids(comp, lambda s: s.Reversed())
    assert len(faces_of(out)) == 7 and _props(solids_of(out)[0])[0] == pytest.approx(-1.0)


@pytest.mark.corpus
def test_export_step_round_trip_keeps_every_solid(corpus_file, tmp_path):
    change = roundtrip_change(corpus_file, tmp_path)
    if corpus_file.name in OCCT_REBUILDS:
        bound, _ = OCCT_REBUILDS[corpus_file.name]
        assert 1e-12 < change <= bound, f"{corpus_file.name}: {change:.3g} (pinned {bound:.3g}): update OCCT_REBUILDS"
    else:
        assert change <= 1e-12, f"{corpus_file.name}: the round trip changes a solid by {change:.3g}"
