"""The independent moment reference (``tests/twins/moment_reference.py``): centroid and
inertia from volumes of cut solids only, against textbook closed forms (moments of a solid
of revolution from its profile, Steiner's theorem for a hole, a rotation applied by
Rodrigues' formula).

Where every cut meets the faces in lines and circles whose p-curves are exact (the box
with a hole) it holds 1e-10 of the part's size and of the largest inertia entry.  Where
the cuts are oblique to curved faces OCCT gives the new edges approximated p-curves (an
ellipse on a cylinder, a circle on a tilted sphere); the reference weighs fluxes through
the solid's own faces, on which those p-curves cost only their error squared: the
rotated spherical cap holds 4e-12 / 3e-11, the cone frustum 4e-11 / 5e-9 (two cuts the
splitter botches next to a fold of the base circle).  A rotated torus or rounded box is
tested here through ``sm.mass_properties`` and BRepGProp only: the reference cuts their
sections by walking (torus, pieces=1: more than 900 s on the busy machine) or at every
one of their many vertex levels (rounded box: 6426 planes, 590 s)."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import build123d as bd
import numpy as np
import pytest
from numpy.polynomial import Polynomial as P
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.gp import gp_Ax1, gp_Dir, gp_Pln, gp_Pnt, gp_Trsf, gp_Vec
from test_occt_quirks import quirk_holds

import surfmod as sm
from surfmod.errors import SurfmodError
from surfmod.tolerances import MASS_AGREEMENT_RTOL
from surfmod.occ.properties import gprops
from twins.moment_reference import (GAUSS_W, KRONROD_W, KRONROD_X, PACE_CUTS, critical_levels, cut_volumes,
                                          moment_reference, _intervals, _nodes)

AXIS, ANGLE, SHIFT = np.array([1.0, 2.0, 3.0]) / math.sqrt(14), 0.7, np.array([3.0, -2.0, 5.0])


def rodrigues(axis, angle):
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def moved(shape):
    """``shape`` rotated by ANGLE about AXIS through the origin, then moved by SHIFT."""
    rot, move = gp_Trsf(), gp_Trsf()
    rot.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(*AXIS)), ANGLE)
    move.SetTranslation(gp_Vec(*SHIFT))
    return BRepBuilderAPI_Transform(shape, move.Multiplied(rot), True).Shape()


def revolution(rho2: P, z0: float, z1: float):
    """Volume, centroid and inertia (about the centroid) of the solid of revolution about
    z with squared radius ``rho2(z)`` on ``[z0, z1]``: ``V = ∫π ρ²``, ``∫z = ∫π ρ² z``,
    ``∫z² = ∫π ρ² z²``, ``∫x² = ∫y² = ∫π ρ⁴ / 4`` (discs), exactly (polynomials)."""
    z = P([0, 1])

    def integral(p):
        q = p.integ()
        return q(z1) - q(z0)

    v = integral(math.pi * rho2)
    zc = integral(math.pi * rho2 * z) / v
    zz = integral(math.pi * rho2 * z * z) - v * zc * zc
    xx = integral(math.pi * rho2 * rho2 / 4)
    return v, np.array([0, 0, zc]), np.diag([xx + zz, xx + zz, 2 * xx])


def torus_moments(big, small):
    """Pappus for the volume; the textbook inertia of a solid torus about its centre."""
    v = 2 * math.pi ** 2 * big * small * small
    across, along = v * (big * big / 2 + 5 * small * small / 8), v * (big * big + 3 * small * small / 4)
    return v, np.zeros(3), np.diag([across, across, along])


#: a point segment, quarter disc and ball octant of radius ρ: their measure and the first
#: and second moments of one coordinate (u ≥ 0 from the flat side)
def _rounded_pieces(rho):
    return {1: (rho, rho ** 2 / 2, rho ** 3 / 3),
            2: (math.pi * rho ** 2 / 4, rho ** 3 / 3, math.pi * rho ** 4 / 16),
            3: (math.pi * rho ** 3 / 6, math.pi * rho ** 4 / 16, math.pi * rho ** 5 / 30)}


def rounded_box_moments(sides, rho):
    """Volume, centroid and inertia of a box of ``sides`` centred at the origin with every
    edge filleted by ``rho`` (the core box grown by a ball): 27 pieces, one per choice of
    below / inside / above the core along each axis; a piece outside the core along k axes
    is the core's cross-section times a segment, quarter disc or ball octant."""
    half = np.asarray(sides, dtype=float) / 2 - rho
    pieces = _rounded_pieces(rho)
    v, sq = 0.0, np.zeros(3)
    for where in np.ndindex(3, 3, 3):
        out = [w != 1 for w in where]
        k = sum(out)
        m0 = pieces[k][0] if k else 1.0
        v += m0 * math.prod(2 * half[i] for i in range(3) if not out[i])
        for i in range(3):
            rest = math.prod(2 * half[j] for j in range(3) if not out[j] and j != i)
            if out[i]:  # x = ±(half + u): ∫(half + u)² over the rounded piece
                _, m1, m2 = pieces[k]
                sq[i] += (half[i] ** 2 * m0 + 2 * half[i] * m1 + m2) * rest
            else:
                sq[i] += 2 * half[i] ** 3 / 3 * rest * m0
    return v, np.zeros(3), np.diag([sq[1] + sq[2], sq[0] + sq[2], sq[0] + sq[1]])


def rounded_box(sides, rho):
    return bd.fillet(bd.Box(*sides).edges(), rho)


def test_closed_forms_of_the_torus_and_rounded_box_hold_for_simple_cases():
    # the rounded box's 27 pieces: with ρ → 0 a box, with the core → 0 a ball
    v, _, inertia = rounded_box_moments((4, 3, 2), 1e-300)
    assert math.isclose(v, 24, rel_tol=1e-15) and np.allclose(np.diag(inertia), [26, 40, 50], rtol=1e-15)
    v, _, inertia = rounded_box_moments((2, 2, 2), 1.0)
    assert math.isclose(v, 4 * math.pi / 3, rel_tol=1e-15)
    assert np.allclose(np.diag(inertia), 2 / 5 * v, rtol=1e-15)
    # the torus against OCCT's own volume of it (a closed form of its own, 1e-15)
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(bd.Torus(3, 1).wrapped, props, 1e-12, False, False)
    assert math.isclose(props.Mass(), torus_moments(3, 1)[0], rel_tol=1e-14)


@pytest.mark.parametrize("name", ["torus", "rounded box"])
def test_mass_properties_of_a_rotated_and_moved_torus_and_rounded_box(name):
    # surfmod's own integration and BRepGProp against the closed forms, 1e-10 of the
    # part's size (centroid) and of the largest inertia entry; 0.2 s
    shape, (v, c, inertia) = {"torus": (bd.Torus(3, 1).wrapped, torus_moments(3, 1)),
                              "rounded box": (rounded_box((4, 3, 2), 0.5).wrapped,
                                              rounded_box_moments((4, 3, 2), 0.5))}[name]
    q = rodrigues(AXIS, ANGLE)
    c, inertia = q @ c + SHIFT, q @ inertia @ q.T
    solid = moved(shape)
    mine, theirs = sm.mass_properties(solid), gprops(solid, 1e-12)
    length, big = v ** (1 / 3), np.abs(inertia).max()
    for got_v, got_c, got_i in ((mine.volume, mine.centroid, mine.inertia),
                                (theirs["volume"], theirs["centroid"], theirs["inertia"])):
        assert abs(got_v - v) / v < 1e-12
        assert np.abs(np.asarray(got_c) - c).max() / length < 1e-10
        assert np.abs(np.asarray(got_i) - inertia).max() / big < 1e-10


def test_brepgprop_plane_volume_measures_heights_from_the_mirrored_plane():
    # the OCCT 7.9 quirk the reference's fluxes work around (moment_reference._flux): the
    # "volume between the faces and the plane z = 2" of a box's faces is ∫(z + 2) n_z dA,
    # not ∫(z - 2) n_z dA; through the origin the two agree
    box = bd.Box(1, 2, 3).translate((0.3, 0.1, 0.2))  # z from -1.3 to 1.7, top and bottom of area 2
    faces = box.faces().sort_by(bd.Axis.Z)
    bottom, top, box = faces[0].wrapped, faces[-1].wrapped, box.wrapped

    def flux(shape, z):
        props = GProp_GProps()
        BRepGProp.VolumePropertiesGK_s(shape, props, gp_Pln(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)), 1e-12)
        return props.Mass()

    assert math.isclose(flux(top, 0), 2 * 1.7, rel_tol=1e-14) and math.isclose(flux(bottom, 0), 2 * 1.3, rel_tol=1e-14)
    quirk = "test_mass_reference.py::test_brepgprop_plane_volume_measures_heights_from_the_mirrored_plane"
    expected = 2 * (1.7 + 2) if quirk_holds(quirk) else 2 * (1.7 - 2)  # the quirk: (1.7 - 2) * 2 is right
    assert math.isclose(flux(top, 2), expected, rel_tol=1e-14)
    assert math.isclose(flux(bottom, 2), -2 * (-1.3 + 2), rel_tol=1e-14)
    assert math.isclose(flux(box, 2), 6, rel_tol=1e-14)  # a closed shell's volume does not care


def check(shape, volume, centroid, inertia, tol=1e-10, covered=False, r=None, estimate=None):
    """The reference (``r``, or computed) within ``tol`` (relative) of the closed form, its
    estimates within ``estimate`` (default ``tol``); with ``covered``, its error within
    its own estimate."""
    r = moment_reference(shape) if r is None else r
    assert abs(r.volume - volume) / volume < 1e-12
    length = volume ** (1 / 3)
    big = np.abs(inertia).max()
    dc = np.abs(r.centroid - centroid).max()
    di = np.abs(r.inertia - inertia).max()
    assert dc / length < tol and di / big < tol, (dc / length, di / big)
    estimate = tol if estimate is None else estimate
    assert r.centroid_error / length < estimate and r.inertia_error / big < estimate and r.consistency < tol
    if covered:
        assert dc <= r.centroid_error and di <= r.inertia_error, (dc, r.centroid_error, di, r.inertia_error)
    return r


def test_kronrod_rule_is_exact_to_degree_31_and_holds_the_gauss_rule():
    x, w = np.polynomial.legendre.leggauss(10)
    assert np.allclose(KRONROD_X[1::2], x, rtol=0, atol=1e-15) and np.allclose(GAUSS_W[1::2], w, atol=1e-15)
    for k in range(32):
        assert abs(KRONROD_W @ KRONROD_X ** k - (1 - (-1) ** (k + 1)) / (k + 1)) < 1e-14
    assert abs(KRONROD_W @ KRONROD_X ** 32 - 2 / 33) > 1e-13  # and no further: the rule is what it says


def test_nodes_integrate_a_square_root_end_exactly():
    # ψ(s) = 3s² - 2s³ turns (t - a)^(3/2) at an end into a polynomial in s
    ends = np.array([0.0, 1.0, 3.0])
    t, scale = _nodes(ends, [True, True])
    f = np.where(t < 1, t ** 1.5, np.sqrt(3 - t))
    assert abs(((scale * f) @ KRONROD_W).sum() - (0.4 + 2 / 3 * 2 ** 1.5)) < 1e-14


def test_intervals_merge_close_levels_and_split_long_ones():
    ends, mapped = _intervals(np.array([0.0, 1e-9, 0.5, 4.0]), 1e-6, 2)
    assert ends.tolist() == [0.0, 0.5, 2.25, 4.0] and mapped.all()
    # next to a vertex whose tolerance the first node after ψ (1.4e-5 of the interval in)
    # would come within twice of, the interval is integrated plainly (first node 2.2e-3
    # in); closer still, the level is merged; the last level stays
    levels = np.array([0.0, 1e-3, 0.5, 3.999, 4.0])
    ends, mapped = _intervals(levels, 1e-6, 1, [0, 1e-8, 0, 0, 0])
    assert ends.tolist() == levels.tolist() and mapped.tolist() == [False, True, True, True]
    ends, mapped = _intervals(levels, 1e-6, 1, [0, 2e-6, 0, 0, 0])
    assert ends.tolist() == [0.0, 0.5, 3.999, 4.0] and mapped.tolist() == [True, True, True]
    assert _intervals(levels, 1e-6, 1, [0, 0, 0, 0, 2e-6])[0].tolist() == [0.0, 1e-3, 0.5, 4.0]
    with pytest.raises(SurfmodError, match="shape: its tolerances"):
        _intervals(levels, 1e-6, 1, [1e-2] * 5)


def test_critical_levels_of_elementary_faces():
    assert critical_levels(bd.Cylinder(1, 4).wrapped, (1, 0, 0)).round(12).tolist() == [-1.0, 1.0]
    assert critical_levels(bd.Cylinder(1, 4).wrapped, (0, 0, 1)).round(12).tolist() == [-2.0, 2.0]
    torus = critical_levels(bd.Torus(3, 1).wrapped, (1, 0, 0)).round(12).tolist()
    assert torus == [-4.0, -2.0, 2.0, 4.0]  # the inner equator's saddles too
    # a tilted box has its vertices' levels only
    box = bd.Box(1, 2, 3).rotate(bd.Axis.Z, 30).wrapped
    assert len(critical_levels(box, (1, 0, 0))) == 4


def test_cut_volumes_of_a_sphere_cut_obliquely_are_exact_caps():
    # every plane meets the sphere's parameter lines obliquely, so OCCT approximates the
    # p-curves of the section circles: weighed as slabs' volumes V(t) was 1.3e-11..4.7e-11
    # of the sphere off the cap formula; as fluxes through the sphere's own face, below
    # 6e-13 (1 s)
    radius, centre = 2.0, np.array([0.3, -0.2, 0.5])
    sphere = bd.Sphere(radius).translate(tuple(centre)).wrapped
    a = np.array([1.0, 2.0, 3.0]) / math.sqrt(14)
    heights = a @ centre + np.array([-1.7, -0.9, -0.2, 0.4, 1.1, 1.8])
    v = 4 / 3 * math.pi * radius ** 3
    vt, defect, pieces = cut_volumes(sphere, a, heights, v, centre, 3.0)
    depth = heights - (a @ centre - radius)
    assert pieces == 7 and abs(defect) / v < 1e-12
    assert np.abs(vt - math.pi * depth ** 2 * (3 * radius - depth) / 3).max() / v < 2e-12


HOLE = (0.7, 0.3)


def holed_box():
    return bd.Box(4, 3, 2) - bd.Cylinder(0.5, 3).translate((*HOLE, 0))


@pytest.fixture(scope="module")
def hole_reference():
    """The reference of :func:`holed_box`, cut once for the tests that use it."""
    return moment_reference(holed_box().wrapped)


def test_box_with_an_off_centre_hole(hole_reference):
    r2, (cx, cy) = 0.25, HOLE
    vh = math.pi * r2 * 2
    v = 24 - vh
    first = -vh * np.array([cx, cy, 0])
    second = np.diag([32 - vh * (cx * cx + r2 / 4), 18 - vh * (cy * cy + r2 / 4), 8 - vh / 3])
    second[0, 1] = second[1, 0] = -vh * cx * cy  # Steiner: the hole's ∫xy about its axis is 0
    g = first / v
    central = second - v * np.outer(g, g)
    check(None, v, g, np.trace(central) * np.eye(3) - central, r=hole_reference)


@pytest.mark.corpus  # 18 s on the busy 2-core machine
def test_spherical_cap_moved_and_rotated():
    # every cut but those along z meets the sphere obliquely: approximated p-curves,
    # which cost the volumes of slabs 1e-8 (centroid 9.5e-9, inertia 1.3e-8) and the
    # fluxes 3.8e-12 and 3.4e-11; QUADPACK's estimate stays cautious (1.5e-8)
    radius, z0 = 2.0, 0.5
    above = bd.Box(5, 5, 3, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)).translate((0, 0, z0))
    cap = bd.Sphere(radius) & above
    v, c, inertia = revolution(P([radius * radius, 0, -1]), z0, radius)
    q = rodrigues(AXIS, ANGLE)
    check(moved(cap.wrapped), v, q @ c + SHIFT, q @ inertia @ q.T, covered=True, estimate=1e-7)


@pytest.mark.corpus  # 14 s on the busy 2-core machine
def test_cone_frustum_moved_and_rotated():
    # centroid 4e-11; the inertia 5e-9: two intervals' cuts, next to a fold of the base
    # circle, lose 2e-7 of the volume whichever way they are tried (the splitter's
    # failure, counted in the estimate)
    r1, r2, h = 2.0, 0.8, 3.0
    cone = bd.Cone(r1, r2, h, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN))
    v, c, inertia = revolution(P([r1, (r2 - r1) / h]) ** 2, 0.0, h)
    q = rodrigues(AXIS, ANGLE)
    check(moved(cone.wrapped), v, q @ c + SHIFT, q @ inertia @ q.T, tol=1e-8, covered=True, estimate=1e-6)


def test_a_solid_is_required():
    with pytest.raises(SurfmodError, match="shape: "):
        moment_reference(bd.Box(1, 1, 1).faces()[0].wrapped)


def test_a_run_over_budget_stops_at_the_pace_of_its_first_cuts():
    """A box with six holes: 111 intervals, 2331 planes, about a minute of cutting (the
    static estimate says 37 s).  With a budget of 2 s the run stops within its first
    sweep, as soon as the pace of the cuts so far says it would end past the budget, and
    says so (before, it cut until the deadline, then past it for the rest of a cut)."""
    import re

    part = bd.Box(40, 30, 10)
    for i in range(6):
        part = part - bd.Pos(-15 + 6 * i, 3 * (i % 3) - 3, 0) * bd.Cylinder(1.5 + 0.1 * i, 20)
    with pytest.raises(SurfmodError, match="budget: ") as info:
        moment_reference(part.wrapped, budget=2.0)
    found = re.search(r"at the pace of its cuts \((\d+) intervals along \[1.0, 0.0, 0.0\], (\d+) cut, (\d+) more",
                      str(info.value))
    assert found, str(info.value)
    intervals, cut, later = map(int, found.groups())
    assert PACE_CUTS <= cut < intervals and intervals + later > 100


@pytest.mark.parametrize("moved_side, code, line", [
    ("occt", 0, "REFERENCE CONFIRMS SURFMOD"), ("numpy", 4, "REFERENCE CONFIRMS BREPGPROP")])
def test_mass_command_lets_the_reference_settle_moments(monkeypatch, tmp_path, capsys, moved_side, code, line):
    import dataclasses

    import surfmod as sm
    import surfmod.cli.mass as mass
    from surfmod.cli import main

    path = tmp_path / "hole.step"
    sm.export_step(holed_box(), path)
    real = mass.mass_properties

    def one_side_off(solid, density=1.0, **kw):  # one side's centroid 1e-5 of the size off
        r = real(solid, density, **kw)
        side = kw.get("method", "numpy")
        return dataclasses.replace(r, centroid=np.asarray(r.centroid) + 3e-5) if side == moved_side else r

    monkeypatch.setattr(mass, "mass_properties", one_side_off)
    assert main(["mass", str(path), "--no-progress"]) == code
    out = capsys.readouterr().out
    assert line in out and out.count("REFERENCE") == 1 and "BRepGProp on the faces split 2 x 2" in out
    assert ("DISAGREEMENT" in out) == (code == 4)


@pytest.mark.parametrize("moved_side, code, line", [
    ("occt", 0, "REFERENCE CONFIRMS SURFMOD"), ("numpy", 4, "REFERENCE CONFIRMS BREPGPROP")])
def test_mass_command_asks_gauss_kronrod_when_the_split_cannot_tell(monkeypatch, tmp_path, capsys, moved_side, code,
                                                                    line):
    import surfmod.cli.mass as mass
    import surfmod.uses.mass_reference as refined
    from surfmod.cli import main

    path = tmp_path / "hole.step"
    sm.export_step(holed_box(), path)
    real = mass.mass_properties

    def one_side_off(solid, density=1.0, **kw):
        r = real(solid, density, **kw)
        return dataclasses.replace(r, centroid=np.asarray(r.centroid) + 3e-5) if kw.get(
            "method", "numpy") == moved_side else r

    def unsettled(solid, budget=60.0, **kw):  # as on a file whose split is not exact
        raise SurfmodError("budget: refining the faces 2 x 2 (test)")

    monkeypatch.setattr(mass, "mass_properties", one_side_off)
    monkeypatch.setattr(refined, "refined_props", unsettled)
    assert main(["mass", str(path), "--no-progress"]) == code
    out = capsys.readouterr().out
    assert "REFERENCE SKIPPED: budget: refining the faces 2 x 2 (test)" in out
    assert f"{line}: BRepGProp's Gauss-Kronrod rule agrees with" in out


def test_mass_command_skips_a_reference_over_budget(monkeypatch, tmp_path, capsys):
    import dataclasses

    import surfmod as sm
    import surfmod.cli.mass as mass
    from surfmod.cli import main

    path = tmp_path / "box.step"
    sm.export_step(bd.Box(1, 2, 3), path)
    real = mass.mass_properties
    monkeypatch.setattr(mass, "mass_properties", lambda s, d=1.0, **kw: (
        dataclasses.replace(real(s, d, **kw), centroid=np.asarray(real(s, d, **kw).centroid) + 1e-4)
        if "method" not in kw else real(s, d, **kw)))
    monkeypatch.setattr(mass.mass_reference, "REFERENCE_BUDGET", 1e-6)
    assert main(["mass", str(path), "--no-progress"]) == 4
    out = capsys.readouterr().out
    assert "REFERENCE SKIPPED: budget: refining the faces 2 x 2 would take about" in out and "DISAGREEMENT" in out
    assert "REFERENCE SKIPPED: budget: no time left for the Gauss-Kronrod reference" in out


# -- real parts (the corpus; benchmarks/mass_reference.py runs the reference on all) --------
def _solid(corpus_dir, name, index):
    import surfmod as sm
    from surfmod.occ.topo import solids_of

    return solids_of(sm.import_step(corpus_dir / name).wrapped)[index]


def _against_reference(solid, budget=60.0):
    """``(surfmod's centroid and inertia differences, BRepGProp's, the reference's
    estimates, the reference)``, differences relative to the volume's cube root and the largest inertia entry."""
    import surfmod as sm
    o = gprops(solid, 1e-12)
    ref = moment_reference(solid, o["volume"], budget=budget)
    mine = sm.mass_properties(solid)
    length, big = ref.volume ** (1 / 3), np.abs(ref.inertia).max()

    def rel(c, i):
        return np.abs(np.asarray(c) - ref.centroid).max() / length, np.abs(np.asarray(i) - ref.inertia).max() / big

    estimates = ref.centroid_error / length, ref.inertia_error / big
    return rel(mine.centroid, mine.inertia), rel(o["centroid"], o["inertia"]), estimates, ref


@pytest.mark.corpus  # 2 s
def test_brepgprop_product_of_inertia_quirk_on_a_plain_cylinder(corpus_dir):
    # cadquery's blue cylinder (r 5, h 10, axis z through (10, 5)): by symmetry Ixy = 0.
    # BRepGProp (eps 1e-12) gives -4.7e-5, 4e-9 of Ixx: an OCCT quirk; surfmod's and the
    # reference's agree with the closed form
    solid = _solid(corpus_dir, "cadquery_red_cube_blue_cylinder.step", 0)
    v = math.pi * 25 * 10
    exact = np.diag([v * (3 * 25 + 100) / 12] * 2 + [v * 25 / 2])
    (mc, mi), (oc, oi), (ec, ei), ref = _against_reference(solid)
    assert np.abs(ref.inertia - exact).max() / exact.max() < 1e-10 and np.allclose(ref.centroid, (10, 5, 5), atol=1e-9)
    assert mc < 1e-10 and mi < 1e-10 and ec < 1e-10 and ei < 1e-9
    quirk = "test_mass_reference.py::test_brepgprop_product_of_inertia_quirk_on_a_plain_cylinder"
    assert (oi > 1e-9 and abs(gprops(solid, 1e-12)["inertia"][0, 1]) / exact.max() > 1e-9) == quirk_holds(quirk)


REAL_SOLIDS = [
    # 23 faces (17 planes, 6 cylinders), loose vertices (1e-5) beside 1e-7 faces: 2100 planes
    ("pythonocc_face_recognition_sample_part.stp", 0),
    ("pythonocc_as1_pe_203.stp", 3),  # a bolt of the assembly: 6 planes, 2 cylinders
    ("cadquery_red_cube_blue_cylinder.step", 1),  # the red cube
]


@pytest.mark.corpus  # 97 s, 19 s and 2 s of the busy machine's wall time
@pytest.mark.parametrize("name, index", REAL_SOLIDS, ids=[f"{n}#{i}" for n, i in REAL_SOLIDS])
def test_surfmod_moments_match_the_reference_on_real_parts(corpus_dir, name, index):
    (mc, mi), (oc, oi), (ec, ei), _ = _against_reference(_solid(corpus_dir, name, index), budget=300)
    assert ec < 1e-10 and ei < 1e-10  # the reference is sure of itself here ...
    assert mc < 1e-9 and mi < 1e-9  # ... and surfmod is within the 1e-9 of it
    assert oc < 1e-9 and oi < 1e-9  # (so is BRepGProp on these)


# -- the refined reference (surfmod.uses.mass_reference.refined_props) ----------------------------------
def test_refined_reference_settles_brepgprop_on_a_torus_fillet(corpus_dir):
    """nist_ftc_11, a washer with two torus beads: BRepGProp's inertia at eps 1e-13 is 5e-7
    off the closed form from its profile (its adaptive rule converges the volume only); on
    faces split 2 x 2 and 4 x 4 it converges to it, as surfmod's is."""
    import mpmath as mp

    from surfmod.uses.mass_reference import refined_props

    mp.mp.dps = 30
    h, rr = mp.mpf("0.425"), mp.mpf("1.5")
    t2 = mp.asin(h / rr)
    # the profile in the (r, z) half plane, counter-clockwise: outer wall, outer bead, top,
    # inner bead, inner wall (the bottom and top lines carry no dz)
    def region(a, b):  # ∫∫ r^a z^b dA = ∮ r^(a+1) / (a+1) z^b dz
        f = lambda r, z: r ** (a + 1) / (a + 1) * z ** b  # noqa: E731
        arc = lambda c: lambda t: f(c + rr * mp.cos(t), rr * mp.sin(t)) * rr * mp.cos(t)  # noqa: E731
        return (mp.quad(lambda z: f(mp.mpf("31.5"), z), [-1.5, 0]) + mp.quad(arc(30), [0, mp.pi / 2, mp.pi - t2])
                + mp.quad(arc(mp.mpf("17.5")), [t2, mp.pi / 2, mp.pi]) + mp.quad(lambda z: f(16, z), [0, -1.5]))
    v = 2 * mp.pi * region(1, 0)
    zc = 2 * mp.pi * region(1, 1) / v
    xx, zz = mp.pi * region(3, 0), 2 * mp.pi * region(1, 2) - v * zc ** 2
    washer = _solid(corpus_dir, "nist_ftc_11_asme1_rb.stp", 0)
    exact = np.diag([float(xx + zz)] * 2 + [float(2 * xx)])
    big = exact.max()
    occ = gprops(washer, 1e-13)
    assert abs(occ["volume"] / float(v) - 1) < 1e-12
    quirk = "test_mass_reference.py::test_refined_reference_settles_brepgprop_on_a_torus_fillet"
    assert (np.abs(occ["inertia"] - exact).max() / big > 1e-7) == quirk_holds(quirk)
    ref = refined_props(washer)
    assert ref.converged and ref.splits >= 2
    assert abs(ref.volume / float(v) - 1) < 1e-13 and abs(ref.centroid[2] - float(zc)) < 1e-13 * 32
    assert np.abs(ref.inertia - exact).max() / big < 1e-11
    mine = sm.mass_properties(washer)
    assert np.abs(mine.inertia - exact).max() / big < 1e-12


def test_refined_reference_keeps_the_reference_point_and_refuses_past_its_budget():
    from surfmod.occ.properties import vertex_mean
    from surfmod.uses.mass_reference import refined_props
    from surfmod.occ.properties import gprops_about

    part = (bd.Box(4, 3, 2) - bd.Cylinder(0.5, 3).translate((*HOLE, 0))).wrapped
    g, o = gprops_about(part, vertex_mean(part)), gprops(part, 1e-13)  # BRepGProp's loop, face by face
    assert g["volume"] == pytest.approx(o["volume"], rel=1e-15)
    ref = refined_props(part)
    assert np.allclose(ref.location, vertex_mean(part), rtol=0, atol=0) and ref.converged
    with pytest.raises(SurfmodError, match="budget: refining the faces 2 x 2"):
        refined_props(part, budget=0.0)
    with pytest.raises(SurfmodError, match="shape: "):
        refined_props(bd.Box(1, 1, 1).faces()[0].wrapped)


#: corpus solids whose integrators disagree by more than 1e-9 because the file itself
#: leaves those digits open (boundary_ambiguity 1.3e-4 to 4e-3), each with surfmod's distance
#: from the Gauss-Kronrod rule measured when it was named (a record: the test does not run
#: the rule on them, which would add two and a half minutes); surfmod's own digits there are
#: settled (order 12, 16, 24 agree to 1e-16).  Face by face (BRepGProp_Vinert against
#: BRepGProp_VinertGK about the same point) the difference sits on faces whose boundary
#: does not close: on the MAINBODY parts three B-spline faces whose p-curve loops leave
#: 2-D gaps of 1.7e-3 to 2.1e-3 between consecutive edges; on pythonocc_11752 and
#: occt_linkrods B-spline faces whose edges stray 2e-4 to 3e-3 off them (some trimmed past
#: the surface's knot range), so the two faces of an edge meet nowhere and the fields each
#: integrator takes through the gap give it other digits
AMBIGUOUS = {
    ("occt_linkrods.step", 0): 1.9e-9,
    ("stepcode_MAINBODY_BACK.stp", 0): 1.6e-5,
    ("stepcode_MAINBODY_FRONT.stp", 0): 7.5e-6,
    ("pythonocc_11752.stp", 0): 6.2e-8,
    ("pythonocc_Ventilator.stp", 0): 2.5e-8,
    # Creo 2021: boundary_ambiguity 1.28e-4; 1.54e-9 from the Gauss-Kronrod rule (its error
    # 8e-12), 1.63e-9 from plain BRepGProp, 1.65e-9 from the refined reference
    ("asitus_SHIELD_INTEGRATED.stp", 0): 1.7e-9,
    # OCCT's test part for its bug 27693 (ST-Developer 15): 60 of its 254 edges stray 1e-4
    # to 9.2e-3 from their p-curves' images, boundary_ambiguity 9.3e-5; 2.85e-7 from the
    # Gauss-Kronrod rule (its error 2.3e-11), 1.05e-7 from the refined reference (not
    # settled: its last split moved the volume 7e-9), 9.0e-12 from plain BRepGProp
    ("occt_cornetta.stp", 0): 2.9e-7,
}


#: solids whose refinement changes them (the split re-fits p-curves: axom's B-spline sphere
#: moves by 7.6e2 of the tolerance), so they go to the Gauss-Kronrod rule without it (its
#: refinements cost 65 s)
UNREFINABLE = {("axom_boxed_sphere.step", 0)}


def _off(ref, mine):
    from surfmod.uses.mass_reference import relative_differences

    d = relative_differences(mine, ref)
    return max(d["volume"], d["centroid"], d["inertia"])


@pytest.mark.corpus  # 1-100 s per file (the refinements of the faces, the Gauss-Kronrod rule)
def test_surfmod_matches_an_independent_reference_on_every_corpus_solid(corpus_file):
    """On every solid of the corpus surfmod's volume, centroid and inertia are within 1e-9
    (the issue's goal) of an independent reference, whatever plain BRepGProp says:

    * the refined reference, where it has settled (its last refinement moved every
      quantity by less than 1e-10);
    * where it has not (its split changes the solid: ShapeUpgrade fits p-curves again on
      stepcode_dm1's B-spline solids, stepcode_TAIL_TURBINE, build123d's screw thread,
      axom's B-spline sphere, nist_ctc_05; those in :data:`UNREFINABLE` without trying),
      BRepGProp's Gauss-Kronrod rule with the moments converged, its own error estimate
      below 1e-9;
    * on the solids named in :data:`AMBIGUOUS` the file leaves more than 1e-9 open: there
      surfmod is within the command's 1e-7 of plain BRepGProp (the Ventilator within its
      boundary ambiguity), and a new one fails here until it is named."""
    from surfmod.uses.mass_reference import kronrod_props
    from surfmod.uses.mass_reference import refined_props
    from surfmod.occ.topo import solids_of
    from surfmod.uses.mass import boundary_ambiguity

    for i, solid in enumerate(solids_of(sm.import_step(corpus_file).wrapped)):
        key = (corpus_file.name, i)
        mine = sm.mass_properties(solid, estimate_error=False)
        if key in AMBIGUOUS:
            # no reference settles what the file leaves open: plain BRepGProp, no refinement
            # (linkrods' refined reference alone took 94 s)
            o = gprops(solid, 1e-13)
            plain = SimpleNamespace(volume=o["volume"], area=o["area"], centroid=o["centroid"], inertia=o["inertia"])
            limit = max(MASS_AGREEMENT_RTOL, boundary_ambiguity(solid)) if key == ("pythonocc_Ventilator.stp", 0) else (
                MASS_AGREEMENT_RTOL)
            assert _off(plain, mine) < limit, (key, _off(plain, mine))
            continue
        estimate = math.inf
        if key not in UNREFINABLE:
            # bounded by its splits (a count: SPLITS), not by the clock of a loaded machine
            ref = refined_props(solid, budget=math.inf)
            estimate = max(ref.changes[k] for k in ("volume", "centroid", "inertia"))
            if estimate < 1e-10:
                assert _off(ref, mine) < 1e-9, (key, _off(ref, mine))
                continue
        gk = kronrod_props(solid, 1e-10)
        assert gk.error < 1e-9 and _off(gk, mine) < 1e-9, (key, _off(gk, mine), gk.error, estimate)


def test_brepgprop_inertia_quirk_on_a_b_spline_solid_settled_by_gauss_kronrod(corpus_dir):
    """An OCCT quirk, pinned: on stepcode_dm1's solid 4 (B-spline faces, edges that close to
    1e-13) plain BRepGProp's inertia is 6e-9 of its largest entry off, at eps 1e-13 as at
    1e-9 (its adaptive rule converges only the volume), where its own Gauss-Kronrod rule
    with the moments converged and surfmod agree to 1e-12."""
    from surfmod.uses.mass_reference import kronrod_props

    solid = _solid(corpus_dir, "stepcode_dm1-id-214.stp", 4)
    mine = sm.mass_properties(solid, estimate_error=False)
    gk = kronrod_props(solid, 1e-10)
    o = gprops(solid, 1e-13)
    plain = dataclasses.replace(gk, volume=o["volume"], centroid=o["centroid"], inertia=o["inertia"])
    assert gk.error < 1e-11 and _off(gk, mine) < 1e-11
    quirk = "test_mass_reference.py::test_brepgprop_inertia_quirk_on_a_b_spline_solid_settled_by_gauss_kronrod"
    assert (_off(gk, plain) > 3e-9) == quirk_holds(quirk)
