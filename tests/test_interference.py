"""Interference report: overlap volumes, distances, contact against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm

import build123d as bd


def test_overlapping_boxes():
    r = sm.interference(bd.Box(2, 2, 2), bd.Box(2, 2, 2).translate((1.5, 0.5, 0)))
    assert r.overlap_volume == pytest.approx(0.5 * 1.5 * 2, rel=1e-12)
    assert r.interferes and not r.contact and r.distance == 0.0 and r.status == "interference"


def test_sphere_lens():
    d = 1.2
    r = sm.interference(bd.Sphere(1), bd.Sphere(1).translate((d, 0, 0)))
    lens = math.pi * (4 + d) * (2 - d) ** 2 / 12
    assert r.overlap_volume == pytest.approx(lens, rel=1e-9)


def test_contained_sphere():
    r = sm.interference(bd.Box(4, 4, 4), bd.Sphere(1))
    assert r.overlap_volume == pytest.approx(4 / 3 * math.pi, rel=1e-12)
    assert "100 %" in str(r)


def test_clearance_and_closest_points():
    r = sm.interference(bd.Box(2, 2, 2), bd.Sphere(1).translate((0.3, 0.2, 3)))
    assert r.overlap_volume == 0.0 and not r.interferes and not r.contact
    assert r.distance == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(r.point_a, (0.3, 0.2, 1), atol=1e-9)
    assert np.allclose(r.point_b, (0.3, 0.2, 2), atol=1e-9)
    assert "CLEARANCE" in str(r) and "minimum distance 1" in str(r)


def test_face_contact():
    r = sm.interference(bd.Box(2, 2, 2), bd.Box(1, 1, 1).translate((0, 0, 1.5)))
    assert r.contact and not r.interferes and r.distance <= 1e-12
    assert r.overlap_volume < 1e-12 and r.status == "contact"


def test_surfmod_faces_and_step(tmp_path):
    from test_mass import spline_block

    faces, vol = spline_block()
    p = tmp_path / "box.step"
    sm.export_step(bd.Box(1, 1, 1).translate((1, 1.5, 0.5)), p)  # lies inside the block's footprint
    r = sm.interference(faces, str(p))
    assert r.overlap_volume == pytest.approx(1.0, rel=1e-9)
    assert r.volume_a == pytest.approx(vol, rel=1e-9)


def test_bad_input(tmp_path):
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.interference(bd.Box(1, 1, 1), bd.Box(1, 1, 1), tolerance=0)
    with pytest.raises(sm.SurfmodError, match="b: no such file"):
        sm.interference(bd.Box(1, 1, 1), tmp_path / "nope.step")
    with pytest.raises(sm.SurfmodError, match="a: .*closed"):
        sm.interference(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), bd.Box(1, 1, 1))
