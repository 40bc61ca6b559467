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


@pytest.fixture
def brep_fails(monkeypatch):
    def refuse(*args, **kwargs):
        raise femesh._GmshFailure("Invalid boundary mesh (overlapping facets) on surface 1 (forced)")

    monkeypatch.setattr(femesh, "_run_gmsh", refuse)


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


@pytest.mark.corpus
def test_11752_triangulation_crosses_itself(tmp_path):
    """pythonocc_11752.stp: gmsh cannot mesh its B-rep (overlapping facets), and the
    fallback cannot either: its measured triangulation, watertight with 0 admesh repairs,
    still has a triangle edge crossing another face's triangle (tangent B-spline/torus
    blends whose chords cross), which gmsh's boundary recovery rejects.  The fallback
    reports that instead of meshing a self-intersecting boundary."""
    from conftest import CORPUS

    shape = sm.import_step(CORPUS / "pythonocc_11752.stp").wrapped
    with pytest.raises(femesh._GmshFailure, match="segment and a facet intersect"):
        femesh._triangulation_attempt(shape, tmp_path / "part.msh", 40.0, 1)
