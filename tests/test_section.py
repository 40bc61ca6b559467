"""Planar sections (BRepAlgoAPI_Section, NumPy-sampled) and their DXF/SVG/PNG export."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import surfmod as sm

import build123d as bd


def test_sphere_section_is_circle():
    s = sm.section(bd.Sphere(2).translate((1, 2, 3)), (0, 0, 4), (0, 0, 1))
    assert len(s.wires) == 1 and s.closed == [True]
    p = s.polylines[0]
    r = math.sqrt(3)
    assert np.abs(np.linalg.norm(p - (1, 2, 4), axis=1) - r).max() < 1e-12
    assert np.abs(p[:, 2] - 4).max() < 1e-12
    assert s.length == pytest.approx(2 * math.pi * r, rel=1e-12)
    # the polygon area converges to pi r^2 (chord error only)
    assert abs(s.areas()[0]) == pytest.approx(math.pi * 3, rel=2e-3)


def test_oblique_sphere_section_radius():
    n = np.array([1.0, 2.0, 2.0]) / 3
    s = sm.section(bd.Sphere(2), n * 1.5, n)
    p = s.polylines[0]
    assert np.abs(np.linalg.norm(p - n * 1.5, axis=1) - math.sqrt(4 - 2.25)).max() < 1e-12
    assert np.abs((p - n * 1.5) @ n).max() < 1e-12
    q = s.polylines_2d()[0]
    assert np.abs(np.linalg.norm(q, axis=1) - math.sqrt(1.75)).max() < 1e-12


def test_box_perimeter_and_hole():
    s = sm.section(bd.Box(2, 3, 4), (0, 0, 0.5), (0, 0, 1))
    assert s.length == pytest.approx(10.0, rel=1e-14)
    assert abs(s.areas()[0]) == pytest.approx(6.0, rel=1e-14)
    holed = sm.section(bd.Box(2, 3, 4) - bd.Cylinder(0.5, 5), (0, 0, 0.5), (0, 0, 1))
    assert len(holed.wires) == 2 and all(holed.closed)
    assert holed.length == pytest.approx(10 + math.pi, rel=1e-12)
    hole = min(holed.polylines, key=lambda p: np.ptp(p[:, 0]))
    assert np.abs(np.linalg.norm(hole[:, :2], axis=1) - 0.5).max() < 1e-12


def test_spline_surface_section():
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    net[..., 2] = np.random.default_rng(3).random((4, 4))
    surf = sm.BezierSurface(net)
    s = sm.section(surf, (1.5, 0, 0), (1, 0, 0))
    assert len(s.wires) == 1 and s.closed == [False]
    p = s.polylines[0]
    assert np.abs(p[:, 0] - 1.5).max() < 1e-7
    # every sampled point lies on the surface: compare z with the NumPy surface at x = 1.5
    u = np.full(len(p), 0.5)
    v = p[:, 1] / 3
    assert np.abs(surf.points(u, v)[:, 2] - p[:, 2]).max() < 1e-6


def test_plane_missing_part_is_empty(tmp_path):
    s = sm.section(bd.Box(2, 2, 2), (0, 0, 5), (0, 0, 1))
    assert s.empty and s.length == 0 and "empty" in str(s)
    with pytest.raises(sm.SurfmodError, match="nothing to export"):
        sm.export_dxf(s, tmp_path / "e.dxf")
    assert not (tmp_path / "e.dxf").exists()


def test_plane_on_planar_face_is_refused():
    with pytest.raises(sm.SurfmodError, match="plane_normal: .*parallel"):
        sm.section(bd.Box(2, 2, 2), (0, 0, 1), (0, 0, -1))


@pytest.mark.parametrize("kw, arg", [({"plane_normal": (0, 0, 0)}, "plane_normal"),
                                     ({"plane_origin": (0, 0)}, "plane_origin"),
                                     ({"samples": 1}, "samples"),
                                     ({"x_axis": (0, 0, 1)}, "x_axis")])
def test_bad_arguments(kw, arg):
    args = {"plane_origin": (0, 0, 0), "plane_normal": (0, 0, 1)} | kw
    with pytest.raises(sm.SurfmodError, match=arg):
        sm.section(bd.Box(1, 1, 1), **args)


def test_dxf_svg_png_round_trip(tmp_path):
    import ezdxf

    s = sm.section(bd.Box(2, 3, 4) - bd.Cylinder(0.5, 5), (0, 0, 0.5), (0, 0, 1))
    # exact entities: the box's four sides as LINEs, the hole as one CIRCLE
    assert sm.export_dxf(s, tmp_path / "s.dxf") == 5
    msp = ezdxf.readfile(tmp_path / "s.dxf").modelspace()
    lines, circles = msp.query("LINE"), msp.query("CIRCLE")
    assert len(lines) == 4 and len(circles) == 1
    ends = np.array([[*ln.dxf.start][:2] for ln in lines] + [[*ln.dxf.end][:2] for ln in lines])
    np.testing.assert_allclose(np.ptp(ends, axis=0), (2, 3), atol=1e-12)
    assert circles[0].dxf.radius == 0.5 and np.allclose([*circles[0].dxf.center][:2], 0.0, atol=1e-12)
    # 3-D polylines pass through as POLYLINE entities
    assert sm.export_dxf([s.polylines[0]], tmp_path / "p3.dxf") == 1
    assert len(ezdxf.readfile(tmp_path / "p3.dxf").modelspace().query("POLYLINE")) == 1

    assert sm.export_svg(s, tmp_path / "s.svg") == 2
    root = ET.parse(tmp_path / "s.svg").getroot()
    paths = root.findall(".//{http://www.w3.org/2000/svg}path")
    assert len(paths) == 2 and all(p.get("d").endswith("Z") for p in paths)

    s.preview(tmp_path / "s.png")
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_failed_export_keeps_existing_file(tmp_path):
    target = tmp_path / "keep.dxf"
    target.write_text("old")
    with pytest.raises(sm.SurfmodError, match=r"curves\[0\]"):
        sm.export_dxf([np.zeros((1, 2))], target)
    assert target.read_text() == "old"
    with pytest.raises(sm.SurfmodError, match="path"):
        sm.export_svg([np.zeros((3, 2))], tmp_path / "no" / "x.svg")
    with pytest.raises(sm.SurfmodError, match="path"):
        sm.export_dxf([np.zeros((3, 2))], tmp_path / "x.txt")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.dxf"]
