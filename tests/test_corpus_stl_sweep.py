"""STL at every tolerance from 1e-4 to 1e-2 of the bounding-box diagonal (issue 25):
every closed solid of the corpus gives a watertight, outward-oriented STL that admesh
does not repair, with positive volume, at both ends of the range (every file: cheap),
and the written STL is within the tolerance of the exact faces at all five tolerances
on a named subset (the judge, BRepExtrema per sample, is the slow part).

Where the model itself is off by more than the tolerance the mesh says so
(``info["faces_over_tolerance"]``, each face within its declared tolerance): on
axom_boxed_sphere.step the p-curves of the sphere patches stray 0.055 from their 3-D
edges (the edges' declared tolerance), so below 3e-3 of the diagonal its STL is held
to the deviation it reports, not to the tolerance.  test_corpus_mesh.py checks every
file at 1e-3 through the command.
"""

from __future__ import annotations

import re

import build123d as bd
import pytest
from conftest import CORPUS, CORPUS_FILES
from stlcheck import admesh_stats, needs_admesh
from test_corpus_mesh import MODEL_DEFECTS, _check_stl, _independent_deviation

import surfmod as sm
from surfmod.meshing.figures import shape_diagonal
from surfmod.occ.properties import gprops
from surfmod.occ.topo import solids_of

#: the tolerances swept, relative to the bounding-box diagonal
RELATIVE = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4)
#: the files whose STL is judged at every tolerance: small parts of several writers and
#: kinds (spheres, cylinders, a screw's tori, an assembly; B-spline patches whose model is
#: off by more than the finest tolerances, axom_boxed_sphere; occt_linkrods, whose 11
#: B-spline faces a second BRepMesh pass used to leave 1.2-1.5 x the tolerance off at 1e-4)
DEVIATION_FILES = (
    "axom_boxed_sphere.step", "axom_revolved_sphere.step", "axom_sliced_cylinder.step",
    "cadquery_red_cube_blue_cylinder.step", "nist_ctc_03_asme1_rc.stp", "nist_ftc_06_asme1_rd.stp",
    "nist_ftc_10_asme1_rb.stp", "occt_linkrods.step", "occt_screw.step", "stepcode_sg1-c5-214.stp",
    "trimesh_featuretype.STEP",
)


def _part(shape):
    """The solids of ``shape`` as one compound when it has any (a loose face beside a
    solid, as in nist_ctc_04/05, would leave the STL open however good the solid's
    mesh is), else the shape itself (open shells, loose faces)."""
    solids = solids_of(getattr(shape, "wrapped", shape))
    return bd.Compound([bd.Solid(s) for s in solids]) if solids else shape


@pytest.mark.corpus
@needs_admesh
@pytest.mark.parametrize("relative", [1e-2, 1e-4])
def test_closed_solids_give_watertight_outward_stl_at_both_ends(corpus_file, relative, tmp_path):
    part = _part(sm.import_step(corpus_file))
    diag = shape_diagonal(part)  # before any mesh is stored on the part
    tol = relative * diag
    out = tmp_path / "part.stl"
    if corpus_file.name in MODEL_DEFECTS:  # the model's broken solid is named, and only it
        _, _, said, _ = MODEL_DEFECTS[corpus_file.name]
        with pytest.warns(sm.RoundTripWarning, match=said):
            mesh = sm.export_stl(part, out, tolerance=tol)
        assert len(mesh.info["stl_problems"]) == 1 and re.fullmatch(said, mesh.info["stl_problems"][0])
        return
    mesh = sm.export_stl(part, out, tolerance=tol)
    st = _check_stl(part, out, tol)  # admesh: no repair on closed solids; each solid closed and consistently wound
    assert mesh.info["stl_problems"] == [], mesh.info["stl_problems"]  # surfmod's own judge agrees with admesh
    if solids_of(part.wrapped):
        # outward: the enclosed volume is positive and is the solid's, within the
        # tolerance (or the model's own reported deviation) times the area
        props = gprops(part.wrapped, 1e-6)  # 1e-6 of the volume is far below the slack
        slack = max(tol, mesh.info["max_deviation"]) * props["area"] + 1e-6 * props["volume"]
        assert st["Volume"] > 0
        assert abs(st["Volume"] - props["volume"]) <= slack, (st["Volume"], props["volume"], slack)


def test_deviation_files_are_in_the_corpus():
    names = {p.name for p in CORPUS_FILES}
    assert set(DEVIATION_FILES) <= names, set(DEVIATION_FILES) - names


@pytest.mark.corpus
@needs_admesh
@pytest.mark.parametrize("name", DEVIATION_FILES)
def test_stl_within_tolerance_at_every_tolerance(name, tmp_path):
    shape = sm.import_step(CORPUS / name)
    diag = shape_diagonal(shape)
    out = tmp_path / "part.stl"
    for relative in RELATIVE:
        tol = relative * diag
        mesh = sm.export_stl(shape, out, tolerance=tol)
        report = mesh.info["faces_over_tolerance"]
        for face in report:  # the model's own error: within what the model declares
            assert face["deviation"] <= face["model_tolerance"], (relative, face)
        limit = max([tol] + [face["deviation"] for face in report])
        assert mesh.info["max_deviation"] <= limit
        assert _independent_deviation(shape, out, tol) <= limit, (relative, tol, limit)
        assert admesh_stats(out)["Volume"] > 0
