"""Headless PNG rendering: shading, iso-curve overlay, control net, shapes and meshes,
speed for the gallery, atomic writes and bad input."""

from __future__ import annotations


import numpy as np
import pytest

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net


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
