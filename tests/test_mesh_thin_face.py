"""A face narrower than the deflection: BRepMesh leaves it bare, a finer pass meshes it.

In the Analysis Situs plate asitus_Ultima_BP_160x136_v16.step (Inventor via ST-Developer)
faces 27 and 32 are cone slivers 0.09 mm wide between a circle arc (an iso-v line of the
cone) and a nearly straight B-spline whose ends lie on that same iso line.  From a
deflection of 0.25 mm on, BRepMesh puts the B-spline's two ends alone on it, every
boundary node of the face lies on one line in (u, v), and the face is left without
triangles; at 0.2 it meshes.  surfmod's door to BRepMesh (``occ.mesh.mesh_faces``) meshes
such a face alone at a finer deflection (``BARE_FINER``), then the part at the deflection
asked, whose faces take the sliver's edge nodes as they are: every path that meshes a
part gets the same closed mesh."""

from __future__ import annotations

import pytest
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from stlcheck import ADMESH_REPAIRS, admesh_stats, needs_admesh
from test_corpus_mesh import closed_and_oriented

import surfmod as sm
from surfmod.occ.mesh import mesh_faces

NAME = "asitus_Ultima_BP_160x136_v16.step"
SLIVERS = [27, 32]


@pytest.fixture(scope="module")
def plate(corpus_dir):
    return sm.import_step(corpus_dir / NAME)


def _bare_faces(shape) -> list[int]:
    explorer, out, k = TopExp_Explorer(shape, TopAbs_FACE), [], 0
    while explorer.More():
        if BRep_Tool.Triangulation_s(TopoDS.Face(explorer.Current()), TopLoc_Location()) is None:
            out.append(k)
        explorer.Next()
        k += 1
    return out


@pytest.mark.parametrize("deflection, bare", [(0.2, []), (0.25, SLIVERS)])
def test_brepmesh_alone_leaves_the_slivers_bare(plate, deflection, bare):
    copy = BRepBuilderAPI_Copy(plate.wrapped).Shape()  # BRepMesh alone, as OCCT runs it
    BRepMesh_IncrementalMesh(copy, deflection, False, 0.5, False)
    assert _bare_faces(copy) == bare


def test_the_door_meshes_the_slivers_and_keeps_the_deflection_elsewhere(plate):
    got = {k: t for k, _, t in mesh_faces(plate, 0.25)}
    assert all(t is not None for t in got.values())
    # the slivers come out finer, the rest at the deflection asked (BRepMesh's own measure)
    assert all(got[k].deflection < 0.25 / 3 for k in SLIVERS)
    assert max(t.deflection for k, t in got.items() if k not in SLIVERS) > 0.5 * 0.25


@needs_admesh
@pytest.mark.parametrize("tolerance", [0.3, 1.0])
def test_the_plate_meshes_closed_at_coarse_tolerances(tmp_path, plate, tolerance):
    path = tmp_path / "plate.stl"
    mesh = sm.export_stl(plate, path, tolerance=tolerance)
    assert mesh.info["faces_not_meshed"] == [] and mesh.info["max_deviation"] <= tolerance
    assert closed_and_oriented(path)
    stats = admesh_stats(path)
    assert stats["Number of parts"] == 1 and all(stats[k] == 0 for k in ADMESH_REPAIRS), stats
    # OCCT's volume (BRepGProp): every point of the mesh within max_deviation of the surface
    # bounds the volume between them by the area times that deviation
    assert abs(stats["Volume"] - plate.volume) <= plate.area * mesh.info["max_deviation"]
