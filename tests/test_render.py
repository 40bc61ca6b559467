"""Headless PNG rendering: shading, iso-curve overlay, control net, shapes and meshes,
speed for the gallery, atomic writes and bad input."""

from __future__ import annotations


import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.meshing import render


def _read(path):
    import matplotlib.image as mpimg

    return mpimg.imread(str(path))


def _bspline():
    return sm.BSplineSurface(wavy_net(6, 6), (3, 3))


def test_surface_png_is_shaded_with_isocurves(tmp_path):
    p = sm.render(_bspline(), tmp_path / "s.png", isocurves=False)
    img = _read(p)
    assert img.shape[:2] == (500, 600)
    body = img[..., :3][np.any(img[..., :3] < 0.95, axis=2)]
    assert len(body) > 0.05 * 500 * 600  # the surface covers a real part of the picture
    # shaded: many distinct grey levels of the base colour, not one flat fill
    assert len(np.unique(np.round(body[:, 2], 2))) > 10
    iso = _read(sm.render(_bspline(), tmp_path / "i.png", isocurves=True))
    dark = lambda a: int(np.sum(a[..., :3].max(axis=2) < 0.3))  # noqa: E731
    assert dark(iso) > dark(img) + 150  # the iso-curve overlay is drawn


def test_control_net_overlay_is_red(tmp_path):
    img = _read(sm.render(_bspline(), tmp_path / "n.png", control_net=True))
    red = (img[..., 0] > 0.7) & (img[..., 1] < 0.35) & (img[..., 2] < 0.3)
    assert red.sum() > 200
    plain = _read(sm.render(_bspline(), tmp_path / "p.png"))
    assert ((plain[..., 0] > 0.7) & (plain[..., 1] < 0.35) & (plain[..., 2] < 0.3)).sum() == 0


def test_meshes_shapes_and_mixed_lists(tmp_path):
    import build123d as bd

    box = bd.Solid.make_box(2, 3, 1)
    mesh = sm.tessellate(sm.sphere(1.0), 0.05)
    p = sm.render([box, mesh, sm.sphere(0.5).translated((4, 0, 0))], tmp_path / "mix.png")
    img = _read(p)
    assert np.any(img[..., :3] < 0.9)


def test_closed_surface_hides_back_isocurves(tmp_path):
    """On a sphere, only the iso-curves facing the viewer are drawn."""
    from surfmod.meshing.render import _iso_lines

    s = sm.sphere(1.0)
    m = sm.tessellate(s, 0.02)
    eye = np.array([1.0, 0.0, 0.0])
    segs = np.array(_iso_lines(s, m, (9, 9), eye))
    assert len(segs) > 0 and segs.mean(axis=1)[:, 0].min() > -0.1


def test_shade_is_lambert():
    from surfmod.meshing.render import shade

    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    np.testing.assert_allclose(shade(tri, (1, 1, 1), (1, 0, 0))[0, :3], 0.35)
    np.testing.assert_allclose(shade(tri, (0.5, 1, 1), (0, 0, -1))[0, :3], [0.5, 1, 1])


def test_failed_render_keeps_existing_file(tmp_path):
    target = tmp_path / "keep.png"
    target.write_bytes(b"old")
    with pytest.raises(sm.SurfmodError, match="objects"):
        sm.render([_bspline(), "not a surface"], target)
    assert target.read_bytes() == b"old"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["keep.png"]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"path": "x.jpg"}, "path"),
        ({"objects": []}, "objects"),
        ({"objects": 3.0}, "objects"),
        ({"color": (2, 0, 0)}, "color"),
        ({"color": "red"}, "color"),
        ({"iso_count": (1.5, 3)}, "iso_count"),
        ({"dpi": 0}, "dpi"),
    ],
)
def test_bad_input(tmp_path, kwargs, match):
    args = {"objects": _bspline(), "path": tmp_path / "x.png"}
    args.update(kwargs)
    if args["path"] == "x.jpg":
        args["path"] = tmp_path / "x.jpg"
    objects, path = args.pop("objects"), args.pop("path")
    with pytest.raises(sm.SurfmodError, match=match):
        sm.render(objects, path, **args)


# --- pictures in notebooks: _repr_png_ through one helper, png_bytes -------------------------


def _png(data: bytes, size=(400, 300)):
    """The decoded picture of PNG bytes, after checking what a notebook needs of them."""
    import io

    import matplotlib.image as mpimg

    from surfmod.meshing.render import PNG_SIGNATURE

    assert isinstance(data, bytes) and data.startswith(PNG_SIGNATURE)
    img = mpimg.imread(io.BytesIO(data), format="png")
    assert img.shape[:2] == (size[1], size[0])
    rgb = img[..., :3]
    drawn = np.any(rgb < 0.9, axis=2)
    assert rgb.std() > 0.02 and drawn.mean() > 0.003, "blank picture"
    return rgb, drawn


def _holed_plate():
    import build123d as bd

    plate = bd.Box(4, 4, 1) - bd.Cylinder(1.2, 3)
    return sm.from_face(plate.faces().sort_by(bd.Axis.Z)[-1])


@pytest.fixture
def empty_cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    assert not list(tmp_path.iterdir()), "a picture in memory left a file behind"


def test_surface_repr_png(empty_cwd):
    rgb, drawn = _png(_bspline()._repr_png_())
    assert len(np.unique(np.round(rgb[drawn][:, 2], 2))) > 10  # shaded, not a flat fill
    _png(sm.sphere(1.0)._repr_png_())  # a closed analytic surface too


def test_curve_repr_png(empty_cwd):
    c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (2, 0, 1), (3, 1, 0)], 3)
    rgb, drawn = _png(c._repr_png_())
    assert drawn.mean() < 0.05  # a line, not a shaded area
    blue = (rgb[..., 2] > rgb[..., 0] + 0.2) & drawn
    assert blue.sum() > 100


def test_face_read_back_is_drawn_inside_its_trim(empty_cwd):
    face = _holed_plate()
    _rgb, drawn = _png(face._repr_png_())
    # the hole is in the middle of the picture: empty for the trimmed face...
    h, w = drawn.shape
    assert not drawn[h // 2 - 10:h // 2 + 10, w // 2 - 10:w // 2 + 10].any()
    # ...and covered when the untrimmed plane is drawn over the same bounds
    _rgb, full = _png(_untrimmed(face)._repr_png_())
    assert full[h // 2 - 10:h // 2 + 10, w // 2 - 10:w // 2 + 10].all()


def _untrimmed(face):
    from surfmod.meshing.grid import mesh as grid_mesh

    return grid_mesh(face, 8, 8)  # the face's surface over its bounds, trim ignored


def test_mesh_repr_png_simplifies_fine_meshes(empty_cwd):
    from surfmod.meshing.render import PNG_TRIANGLES, display_mesh

    fine = sm.tessellate(sm.sphere(1.0), 1e-4)
    assert len(fine.faces) > 4 * PNG_TRIANGLES
    simple = display_mesh(fine, PNG_TRIANGLES)
    assert 0.3 * PNG_TRIANGLES < len(simple.faces) <= PNG_TRIANGLES
    # the simplified sphere is still the unit sphere within a cell of the clustering grid
    r = np.linalg.norm(simple.vertices, axis=1)
    assert np.abs(r - 1).max() < 2 / np.sqrt(PNG_TRIANGLES) * 2
    _png(fine._repr_png_())
    small = sm.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
    assert len(display_mesh(small, 10).faces) == 2  # quads split, nothing dropped


def test_toolpath_repr_png_shows_passes_and_links(empty_cwd):
    tp = sm.toolpath(_bspline(), sm.Tool("ball", 0.5), stepover=0.4)
    rgb, drawn = _png(tp._repr_png_())
    blue = drawn & (rgb[..., 2] > rgb[..., 0] + 0.3)
    orange = drawn & (rgb[..., 0] > rgb[..., 2] + 0.3)
    assert blue.sum() > 500 and orange.sum() > 5
    passes, links = tp.drawing()
    assert sum(len(p) for p in passes.lines) + sum(len(p) for p in links.lines) >= len(tp.points)


def test_png_bytes_of_shapes_lists_and_sizes(empty_cwd):
    import build123d as bd

    from surfmod.meshing.render import png_bytes

    _png(png_bytes(bd.fillet(bd.Box(4, 4, 4).edges(), 0.8)))
    _png(png_bytes([sm.sphere(0.5), sm.Line((0, 0, 0), (2, 0, 0))], size=(123, 77)), (123, 77))
    for bad, match in [((400,), "size"), ((10, 300), "size"), ((400, 10**6), "size"), ("big", "size")]:
        with pytest.raises(sm.SurfmodError, match=match):
            png_bytes(sm.sphere(1.0), size=bad)
    with pytest.raises(sm.SurfmodError, match="objects"):
        png_bytes("not a surface")
    with pytest.raises(sm.SurfmodError, match="objects"):
        png_bytes([])


def test_repr_png_is_none_when_nothing_can_be_drawn(empty_cwd):
    # IPython then shows the text repr instead of a traceback
    from surfmod.meshing.render import Drawing, repr_png

    assert repr_png(Drawing()) is None
    assert repr_png(object()) is None


def test_objects_of_higher_layers_draw_through_the_drawing_protocol(empty_cwd):
    from surfmod.meshing.render import Drawing, png_bytes, polyline_runs

    class Job:  # what a machining job does: a part and its moves
        def drawing(self):
            runs = polyline_runs(np.array([[0, 0, 1], [4, 0, 1], [4, 4, 1], [0, 4, 0.0]]), np.array([1, 1, 0]))
            return [Drawing(sm.tessellate(sm.sphere(1.0), 0.05)), Drawing(lines=runs[1], line_color=(1, 0, 0, 1))]

    rgb, drawn = _png(png_bytes(Job()))
    assert (drawn & (rgb[..., 0] > 0.8) & (rgb[..., 1] < 0.3)).sum() > 50

    class Broken:
        def drawing(self):
            return ["not a drawing"]

    with pytest.raises(sm.SurfmodError, match="drawing"):
        png_bytes(Broken())


def test_a_shape_whose_faces_all_fail_to_mesh_is_refused(monkeypatch):
    """BRepMesh may leave every face without triangles (brepmesh skips such faces): one
    SurfmodError naming the argument, not NumPy's error on nothing to join."""
    monkeypatch.setattr(render, "brepmesh", lambda *a, **k: [])
    with pytest.raises(sm.SurfmodError, match="objects: the shape has no faces to draw"):
        render._shape_mesh(bd.Box(1, 1, 1))
