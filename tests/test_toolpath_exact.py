"""Drop-cutter heights polished on the exact faces (``drop_cutter(..., exact=True)``):
closed-form cutter locations of ball and flat end mills on a sphere, a cylinder, a tilted
plane and at a box's edge, to rounding, from a deliberately coarse mesh whose own
heights are visibly off."""

from __future__ import annotations

import build123d as bd
import numpy as np

import surfmod as sm
from surfmod.cam.toolpath import drop_cutter

R_BALL = 1.5
COARSE = 0.05  # mesh deflection 0.02: mesh heights miss by ~1e-2, exact ones must not


def test_sphere_closed_form():
    """Ball on a sphere of radius R: centre at distance R + r, z = sqrt((R + r)² − d²) − r."""
    R = 10.0
    xy = np.column_stack([np.linspace(-6, 6, 25), np.linspace(-3, 4, 25)])
    z, contact = drop_cutter(bd.Sphere(R), sm.Tool("ball", R_BALL), xy, tolerance=COARSE, exact=True)
    expected = np.sqrt((R + R_BALL) ** 2 - (xy**2).sum(axis=1)) - R_BALL
    assert np.abs(z - expected).max() <= 1e-12 * R
    # the contact lies on the sphere, on the line from its centre to the ball's
    assert np.abs(np.linalg.norm(contact, axis=1) - R).max() <= 1e-12 * R
    centre = np.column_stack([xy, z + R_BALL])
    assert np.abs(contact - centre * R / (R + R_BALL)).max() <= 1e-12 * R
    mesh, _ = drop_cutter(bd.Sphere(R), sm.Tool("ball", R_BALL), xy, tolerance=COARSE)
    assert np.abs(mesh - expected).max() > 1e-4  # the mesh alone is not exact


def test_cylinder_closed_form():
    """Ball on a cylinder of radius a along x: z = sqrt((a + r)² − y²) − r."""
    a = 5.0
    cylinder = bd.Rot(0, 90, 0) * bd.Cylinder(a, 40)
    xy = np.column_stack([np.linspace(-10, 10, 21), np.linspace(-4, 4, 21)])
    z, _ = drop_cutter(cylinder, sm.Tool("ball", R_BALL), xy, tolerance=COARSE, exact=True)
    assert np.abs(z - (np.sqrt((a + R_BALL) ** 2 - xy[:, 1] ** 2) - R_BALL)).max() <= 1e-12 * a


def test_tilted_plane_closed_form():
    """Plane z = p x + q y + c: the ball touches it r along the normal, so the tip is
    r (sqrt(1 + p² + q²) − 1) above the plane."""
    p, q, c = 0.3, -0.2, 1.0
    corners = [(x, y, p * x + q * y + c) for x, y in ((-10, -10), (10, -10), (-10, 10))]
    plane = sm.plane(*corners)
    xy = np.column_stack([np.linspace(-5, 5, 11), np.linspace(-4, 3, 11)])
    z, _ = drop_cutter(plane, sm.Tool("ball", R_BALL), xy, tolerance=COARSE, exact=True)
    expected = p * xy[:, 0] + q * xy[:, 1] + c + R_BALL * (np.sqrt(1 + p * p + q * q) - 1)
    assert np.abs(z - expected).max() <= 1e-13 * 10


def test_trim_respected_at_a_box_edge():
    """Past the top face's edge the ball rests on the edge (the face's trim), not on the
    face's untrimmed plane: z = h + sqrt(r² − d²) − r, d the distance past the edge."""
    box = bd.Box(10, 10, 4)  # top face z = 2, edges at x = ±5
    d = np.array([-0.5, 0.0, 0.3, 0.9, 1.4])
    xy = np.column_stack([5.0 + d, np.zeros_like(d)])
    z, _ = drop_cutter(box, sm.Tool("ball", R_BALL), xy, tolerance=COARSE, exact=True)
    past = np.maximum(d, 0.0)
    assert np.abs(z - (2.0 + np.sqrt(R_BALL**2 - past**2) - R_BALL)).max() <= 1e-13 * 10


def test_flat_on_a_sphere_closed_form():
    """Flat end of radius R_f on a sphere of radius R, axis d from the sphere's: off the
    summit the rim touches at d − R_f from the axis of the sphere, z = sqrt(R² − (d −
    R_f)²), contact on the sphere towards its summit; over the summit (d < R_f) the
    bottom rests on it, z = R."""
    R = 10.0
    angle = np.linspace(0.0, 2 * np.pi, 15)
    d = np.r_[np.linspace(2.5, 7.0, 15), np.linspace(0.0, 1.0, 15)]
    xy = np.column_stack([d * np.cos(np.r_[angle, angle]), d * np.sin(np.r_[angle, angle])])
    sphere = bd.Rot(35, 20, 0) * bd.Sphere(R)  # the summit is no pole, so no mesh vertex
    z, contact = drop_cutter(sphere, sm.Tool("flat", R_BALL), xy, tolerance=COARSE, exact=True)
    rim = d > R_BALL
    expected = np.where(rim, np.sqrt(R**2 - np.maximum(d - R_BALL, 0.0) ** 2), R)
    assert np.abs(z - expected).max() <= 1e-12 * R
    towards = np.where(rim, d - R_BALL, 0.0) / np.where(d > 0, d, 1.0)
    np.testing.assert_allclose(contact, np.column_stack([xy * towards[:, None], expected]), rtol=0, atol=1e-12 * R)
    mesh, _ = drop_cutter(sphere, sm.Tool("flat", R_BALL), xy, tolerance=COARSE)
    assert np.abs(mesh - expected)[rim].max() > 1e-4 and np.abs(mesh - expected)[~rim].max() > 1e-4  # off


def test_flat_on_a_cylinder_closed_form():
    """Flat end on a cylinder of radius a along x: z = sqrt(a² − (|y| − R_f)²) off its
    crest, a over it."""
    a = 5.0
    cylinder = bd.Rot(0, 90, 0) * bd.Cylinder(a, 40)
    y = np.r_[np.linspace(-4, -2, 7), np.linspace(-1, 1, 5), np.linspace(2, 4, 7)]
    xy = np.column_stack([np.linspace(-10, 10, y.size), y])
    z, _ = drop_cutter(cylinder, sm.Tool("flat", R_BALL), xy, tolerance=COARSE, exact=True)
    assert np.abs(z - np.sqrt(a**2 - np.maximum(np.abs(y) - R_BALL, 0.0) ** 2)).max() <= 1e-12 * a


def test_flat_on_a_tilted_plane_closed_form():
    """Plane z = p x + q y + c: the rim touches at its uphill point, R_f sqrt(p² + q²)
    above the plane at the axis."""
    p, q, c = 0.3, -0.2, 1.0
    corners = [(x, y, p * x + q * y + c) for x, y in ((-10, -10), (10, -10), (-10, 10))]
    plane = sm.plane(*corners)
    xy = np.column_stack([np.linspace(-5, 5, 11), np.linspace(-4, 3, 11)])
    z, _ = drop_cutter(plane, sm.Tool("flat", R_BALL), xy, tolerance=COARSE, exact=True)
    expected = p * xy[:, 0] + q * xy[:, 1] + c + R_BALL * np.hypot(p, q)
    assert np.abs(z - expected).max() <= 1e-13 * 10


def test_a_polish_on_the_floor_never_ignores_a_bump_beside_it():
    """Where a ball rests just on a sphere's foot above the floor (true height 0 .. 0.02 above
    it), the mesh can see the floor as the highest face, and a polish on that face alone
    made its height exact on the wrong face (4.7e-4 low at the default tolerance; 0.080
    with a seed mesh at 5 % of the radius): every face under the tool is polished."""
    part = bd.Pos(0, 0, -2) * bd.Box(30, 30, 2, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)) + bd.Sphere(5)
    part = part - bd.Pos(0, 0, -10) * bd.Box(40, 40, 20, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MAX))
    tool = sm.Tool("ball", 1.0)
    d = np.linspace(5.88, 5.93, 51)
    z, contact = drop_cutter(part, tool, np.column_stack([d * np.cos(0.37), d * np.sin(0.37)]), exact=True)
    closed_form = np.maximum(np.sqrt(np.maximum(36 - d ** 2, 0)) - 1, 0.0)
    assert np.abs(closed_form - z).max() < 1e-12
    on_sphere = closed_form > 0
    assert np.allclose(np.linalg.norm(contact[on_sphere], axis=1), 5.0, atol=1e-12)
