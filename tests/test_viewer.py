"""sm.to_build123d: what the OCP CAD Viewer is handed (types, colours, labels, counts),
checked without starting a viewer."""

import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.cam.roughing import RAPID


def _edges_in(node) -> int:
    return len(node.edges())


def _rgb(node_or_color):
    color = getattr(node_or_color, "color", node_or_color)
    return tuple(round(c, 4) for c in tuple(color)[:3])


@pytest.fixture(scope="module")
def job():
    part = bd.Box(30, 20, 8) - bd.Pos(0, 0, 4) * bd.Cylinder(6, 6)
    return sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 3.0), stepdown=3.0, allowance=0.3),
                                  sm.Finish(sm.Tool("ball", 2.0), scallop=0.2)])


def test_a_surface_is_its_exact_face_and_a_curve_its_edge():
    s = sm.sphere(2.0)
    face = sm.to_build123d(s, color="orange", label="ball")
    assert isinstance(face, bd.Face) and face.label == "ball"
    assert _rgb(face) == _rgb(bd.Color("orange"))
    assert face.area == pytest.approx(4 * np.pi * 4, rel=1e-9)
    edge = sm.to_build123d(sm.Circle((0, 0, 0), (0, 0, 1), 3.0))
    assert isinstance(edge, bd.Edge) and edge.length == pytest.approx(6 * np.pi, rel=1e-12)


def test_build123d_shapes_pass_through_untouched():
    box = bd.Box(1, 2, 3)
    assert sm.to_build123d(box) is box and box.color is None


def test_a_mesh_is_its_triangles():
    m = sm.mesh(sm.plane((0, 0, 0), (4, 0, 0), (0, 3, 0)), 5, 4)
    shape = sm.to_build123d(m)
    assert isinstance(shape, bd.Compound) and shape.label == "mesh"
    tris = m.faces if m.faces.shape[1] == 3 else None
    assert len(shape.faces()) == len(m.faces)
    assert shape.area == pytest.approx(12.0, rel=1e-12)
    assert tris is None or tris.shape[1] == 3


def test_a_mesh_above_the_bound_is_refused_naming_it():
    m = sm.mesh(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), 30, 30)
    from surfmod.occ.polyshapes import triangles

    with pytest.raises(sm.SurfmodError, match="max_triangles"):
        triangles(m.vertices, m.faces, max_triangles=10)


def test_a_job_is_the_part_the_stock_and_each_operation_cuts_and_rapids(job):
    view = sm.to_build123d(job)
    assert view.label == "job"
    labels = [c.label for c in view.children]
    assert labels[:2] == ["part", "stock"]
    assert labels[2:] == [f"{i + 1} {op.name} T{op.tool.number}" for i, op in enumerate(job.operations)]
    assert _edges_in(view.children[1]) == 12  # the stock box
    assert view.children[0].children[0].volume == pytest.approx(bd.Shape.cast(job.part).volume, rel=1e-12)
    colors = set()
    for node, op in zip(view.children[2:], job.operations):
        kinds = {c.label.rsplit(" ", 1)[1]: c for c in node.children}
        assert set(kinds) == {"cuts", "rapids"}
        assert _rgb(kinds["rapids"]) == _rgb(bd.Color("red"))
        colors.add(_rgb(kinds["cuts"]))
        # every move the operation makes is an edge of the view, none twice: a move is a
        # rapid exactly when the operation says so
        pts, kind = op.motion.points, op.motion.kind
        step = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        rapid = kind[1:] == RAPID
        for edges, mine in ((_edges_in(kinds["rapids"]), rapid), (_edges_in(kinds["cuts"]), ~rapid)):
            # moves shorter than OCCT's confusion distance (1e-7) make no edge
            assert int((mine & (step > 1e-6)).sum()) <= edges <= int((mine & (step > 0)).sum())
        cut_length = sum(e.length for e in kinds["cuts"].edges())
        assert cut_length == pytest.approx(op.length, rel=1e-9)
    assert len(colors) == len(job.operations)  # one colour per operation


def test_an_analysis_is_coloured_in_bands_from_low_to_high():
    x, y = np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij")
    s = sm.BSplineSurface.uniform_cubic(np.stack([x, y, np.sin(x + 2 * y)], -1))
    result = sm.analyze(s, "gaussian")
    view = sm.to_build123d(result)
    assert view.label.startswith("analysis gaussian")
    n_tri = sum(len(p.triangles) for p in result.patches)
    assert sum(len(band.faces()) for band in view.children) <= n_tri
    assert sum(len(band.faces()) for band in view.children) >= 0.99 * n_tri  # only slivers left out
    assert all(c.label.startswith("gaussian band") for c in view.children)
    assert len({_rgb(c) for c in view.children}) == len(view.children)


def test_a_toolpath_is_one_coloured_node():
    tp = sm.toolpath(sm.plane((0, 0, 0), (10, 0, 0), (0, 10, 0)), sm.Tool("ball", 1.0), stepover=1.0)
    view = sm.to_build123d(tp)
    assert view.label.startswith("toolpath")
    assert sum(e.length for e in view.edges()) == pytest.approx(tp.length, rel=1e-9)


def test_lists_and_bad_input():
    both = sm.to_build123d([sm.sphere(1.0), sm.torus(3.0, 1.0)], label="pair")
    assert both.label == "pair" and len(both.children) == 2
    with pytest.raises(sm.SurfmodError, match="obj: cannot show a dict"):
        sm.to_build123d({})
