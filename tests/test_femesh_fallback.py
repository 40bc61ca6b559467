"""``fe_mesh`` falls back to surfmod's measured, watertight surface triangulation when gmsh
cannot mesh the B-rep (forced here by making gmsh's B-rep attempts fail): the tetrahedra
keep that triangulation as their boundary, so their volume equals the exact solid's
within area x measured deviation, and the result says how it was made."""

from __future__ import annotations

import math

import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.cli import main
from surfmod.uses import femesh


def _forced_failures(monkeypatch, coarse_triangles: int = -1):
    """gmsh's runs of fe_mesh fail as the test forces: every run on the B-rep (as read,
    healed), and every run filling a triangulation of at most ``coarse_triangles``
    triangles with boundary recovery's failure, as on pythonocc_11752.stp's body region on
    OCCT 8.0; the other runs are the real gmsh in its child process.  A forced failure is
    raised here, not in a child: each child start imports surfmod and this module, seconds
    each, and what a failing child does is test_child.py's."""
    in_child = femesh._gmsh_in_child

    def forced(fn, args, seconds):
        if fn is femesh._run_gmsh:
            raise femesh._GmshFailure("Invalid boundary mesh (overlapping facets) on surface 1 (forced)")
        if fn is femesh._run_gmsh_triangulation and sum(len(t) for _, t in args[0]) <= coarse_triangles:
            raise femesh._GmshFailure("Could not recover boundary mesh: error 2 (forced)")
        return in_child(fn, args, seconds)

    monkeypatch.setattr(femesh, "_gmsh_in_child", forced)


@pytest.fixture
def brep_fails(monkeypatch):
    _forced_failures(monkeypatch)


def test_failed_boundary_recovery_is_retried_finer(monkeypatch):
    from surfmod.meshing.brep import tessellate_shape

    cylinder = bd.Cylinder(1.0, 2.0)
    first = femesh.TRIANGULATION_SHARE * math.sqrt(2**2 + 2**2 + 2**2)
    coarse = len(tessellate_shape(cylinder.wrapped, first).triangles())
    assert len(tessellate_shape(cylinder.wrapped, first * femesh.RECOVERY_RETRY_SHARE).triangles()) > coarse
    _forced_failures(monkeypatch, coarse)
    fe = sm.fe_mesh(cylinder, size=0.4)
    surface = fe.quality["surface"]
    assert surface["tolerance"] == pytest.approx(first * femesh.RECOVERY_RETRY_SHARE, rel=1e-12)
    assert surface["max_deviation"] <= surface["tolerance"] * (1 + 1e-9)
    assert 0 < 2 * math.pi - fe.volume <= surface["volume_bound"]
    assert fe.quality["inverted"] == 0 and fe.quality["SICN"]["min"] > 0


def test_boundary_recovery_failing_twice_names_both_tolerances(monkeypatch):
    _forced_failures(monkeypatch, 10**9)
    first = femesh.TRIANGULATION_SHARE * math.sqrt(2**2 + 2**2 + 2**2)
    # each triangulation attempt (whole solid, then its material regions) tried twice
    pattern = (rf"triangulation: Could not recover boundary mesh: error 2 \(forced\) at tolerance {first:.3g}, "
               rf"Could not recover boundary mesh: error 2 \(forced\) at {first / 2:.3g}")
    with pytest.raises(sm.SurfmodError, match=pattern):
        sm.fe_mesh(bd.Cylinder(1.0, 2.0), size=0.4)


def test_cylinder_from_its_triangulation(brep_fails):
    fe = sm.fe_mesh(bd.Cylinder(1.0, 2.0), size=0.4)
    surface = fe.quality["surface"]
    exact = 2.0 * math.pi
    assert surface["reference_volume"] == pytest.approx(exact, rel=1e-12)
    # the tetrahedra fill the triangulation exactly (boundary kept), so their volume is the
    # polyhedron's: below the convex cylinder's by less than the measured bound
    assert 0 < exact - fe.volume <= surface["volume_bound"]
    assert surface["tolerance"] == pytest.approx(1e-3 * math.sqrt(2**2 + 2**2 + 2**2))
    assert surface["max_deviation"] <= surface["tolerance"] * (1 + 1e-9)
    assert fe.quality["inverted"] == 0 and fe.quality["SICN"]["min"] > 0
    assert fe.quality["measure"] == pytest.approx(fe.volume, rel=1e-12)
    assert "meshed from the measured surface triangulation at tolerance" in str(fe)


def test_box_from_its_triangulation_is_exact(brep_fails):
    fe = sm.fe_mesh(bd.Box(2, 3, 4), size=1.0)
    assert fe.volume == pytest.approx(24.0, rel=1e-13)
    assert np.all(femesh.signed_volumes(fe.points, fe.cells) > 0)


def test_cli_reports_the_fallback(brep_fails, tmp_path, capsys):
    step = tmp_path / "cyl.step"
    sm.export_step(bd.Cylinder(1.0, 2.0), step)
    out = tmp_path / "cyl.msh"
    assert main(["femesh", str(step), "--size", "0.5", "--out", str(out), "--no-progress"]) == 0
    assert "meshed from the measured surface triangulation" in capsys.readouterr().out and out.exists()


def test_void_stays_empty(brep_fails):
    """A solid with an inner void shell: the triangulation's void shell is a hole of the
    volume, so the tetrahedra hold the box minus the void exactly (planar faces)."""
    fe = sm.fe_mesh(bd.Box(4, 4, 4) - bd.Box(2, 2, 2), size=1.0)
    assert fe.volume == pytest.approx(56.0, rel=1e-13)
    assert fe.quality["surface"]["split"] is False
    assert np.all(femesh.signed_volumes(fe.points, fe.cells) > 0)


def test_shells_of_a_hollow_triangulation():
    from surfmod.meshing.brep import tessellate_shape

    mesh = tessellate_shape((bd.Box(4, 4, 4) - bd.Box(2, 2, 2)).wrapped, 0.01)
    shells = femesh.shells_of_triangulation(mesh.vertices, mesh.triangles())
    assert [round(volume, 12) for _, volume in shells] == [64.0, -8.0]
    assert sum(len(tris) for tris, _ in shells) == len(mesh.triangles())


def test_material_regions_drop_the_void():
    from surfmod.occ.booleans import material_regions
    from surfmod.occ.properties import gprops

    hollow = (bd.Box(4, 4, 4) - bd.Box(2, 2, 2)).wrapped
    regions = material_regions(hollow)
    assert len(regions) == 1 and gprops(regions[0])["volume"] == pytest.approx(56.0, rel=1e-12)


def _boss_on_a_bore():
    """The shape of pythonocc_11752.stp's defect, small: a box with a boss below, and a
    void shell (a blind bore above the boss) whose rim circle lies on the outer shell,
    where the boss meets the box, without sharing an edge with it.  The boss is joined to
    the box by that circle only; volume 64 (box) + pi (boss) - pi (bore)."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Solid

    from surfmod.occ.topo import shells_of

    centre = (bd.Align.CENTER, bd.Align.CENTER)
    outer = bd.Box(4, 4, 4, align=(*centre, bd.Align.MIN)) + bd.Cylinder(1, 1, align=(*centre, bd.Align.MAX))
    bore = bd.Cylinder(1, 1, align=(*centre, bd.Align.MIN))
    builder, solid = BRep_Builder(), TopoDS_Solid()
    builder.MakeSolid(solid)
    builder.Add(solid, shells_of(outer.wrapped)[0])
    builder.Add(solid, shells_of(bore.wrapped)[0].Reversed())
    return solid


def test_solid_touching_itself_meshes_from_its_material_regions():
    from surfmod.occ.booleans import material_regions
    from surfmod.occ.properties import gprops

    solid = _boss_on_a_bore()
    assert gprops(solid)["volume"] == pytest.approx(64.0, rel=1e-12)
    regions = sorted(gprops(r)["volume"] for r in material_regions(solid))
    assert regions == pytest.approx([math.pi, 64.0 - math.pi], rel=1e-9)  # the boss, the box with its bore
    fe = sm.fe_mesh(solid, size=0.5)
    surface = fe.quality["surface"]
    assert surface["split"] and surface["regions"] == 2
    assert np.all(femesh.signed_volumes(fe.points, fe.cells) > 0) and fe.quality["SICN"]["min"] > 0
    # the bore stays empty and the boss is filled: the tets hold the solid's volume
    assert abs(fe.volume - 64.0) <= surface["volume_bound"] and abs(fe.volume - 64.0) < 0.1
    assert "of its 2 material regions" in str(fe)


@pytest.mark.corpus
def test_11752_meshes_from_its_material_regions(tmp_path):
    """pythonocc_11752.stp: gmsh cannot mesh its B-rep (ninety 1147 mm long holes of
    radius 1.08 mm: surface 194 gets 82 triangles, the size floor size/10 = 8.6 mm
    exceeding its 6.8 mm circumference, and its facets overlap).  Its measured
    triangulation crosses itself: the solid has two void shells (blind bores, 3 faces
    each) whose rim circles lie on the outer shell, where a boss is attached by that same
    circle only, and the bore's circle edge and the outer shell's are distinct edges
    discretized apart.  Split into its material regions (body and two bosses, sharing
    their circle edges, volumes adding up to BRepGProp's), it meshes."""
    from conftest import CORPUS

    from surfmod.occ.booleans import material_regions
    from surfmod.occ.properties import gprops
    from surfmod.occ.topo import shells_of, solids_of

    shape = sm.import_step(CORPUS / "pythonocc_11752.stp").wrapped
    (solid,) = solids_of(shape)
    assert len(shells_of(solid)) == 3
    with pytest.raises(femesh._GmshFailure, match="segment and a facet intersect"):
        femesh._triangulation_attempt(shape, tmp_path / "part.msh", 86.4, 1, femesh.GMSH_SECONDS)
    regions = material_regions(solid)
    volumes = sorted(gprops(r)["volume"] for r in regions)
    assert len(regions) == 3 and volumes[0] == pytest.approx(volumes[1], rel=1e-12)
    assert sum(volumes) == pytest.approx(gprops(solid)["volume"], rel=1e-9)
    # fe_mesh's own result on this part (its 3 regions meshed, no inverted tet, volume
    # within the bound) is checked by the corpus sweep in test_femesh.py
