"""Every public operation that takes a tolerance refuses one below the floor
(``checks.TOLERANCE_FLOOR`` = 1e-12 of the model size) with a ``SurfmodError`` naming
the argument, and runs at an ordinary one (issue 25, "No hang anywhere").  The floor is
where double precision ends: iterations meant to reach a tolerance below it never stop
(export_svg at 1e-12 of a sphere's section ran 70 s; 1e-300 raised a raw ValueError)."""

from __future__ import annotations

import build123d as bd
import numpy as np
import pytest

import surfmod as sm

SIDES = [sm.Line((0, 0, 0), (1, 0, 0)), sm.Line((1, 0, 0), (1, 1, 0)), sm.Line((1, 1, 0), (0, 1, 0)),
         sm.Line((0, 1, 0), (0, 0, 0))]
COONS = [sm.Line((0, 0, 0), (1, 0, 0)), sm.Line((0, 1, 0), (1, 1, 0)), sm.Line((0, 0, 0), (0, 1, 0)),
         sm.Line((1, 0, 0), (1, 1, 0))]
BOX = bd.Box(2, 2, 2)


def _section():
    return sm.section(bd.Sphere(2), (0, 0, 0), (1, 0, 0))


CASES = {  # name -> call with a tolerance; the model size of each is about 1.4 to 6
    "fill": lambda t: sm.fill(SIDES, "G0", tolerance=t),
    "coons": lambda t: sm.coons(*COONS, tolerance=t),
    "crosscheck": lambda t: sm.crosscheck(sm.offset(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), 0.1, 1e-4),
                                          samples=4, tolerance=t),
    "interference": lambda t: sm.interference(BOX, BOX.translate((3, 0, 0)), tolerance=t),
    "section.polylines_2d": lambda t: _section().polylines_2d(t),
}


@pytest.mark.parametrize("name", sorted(CASES))
@pytest.mark.parametrize("tol", [5e-324, 1e-300, 1e-13])
def test_below_the_floor_is_refused_naming_the_argument(name, tol):
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: .* is below the floor "):
        CASES[name](tol)


@pytest.mark.parametrize("name", sorted(CASES))
def test_an_ordinary_tolerance_runs(name):
    CASES[name](1e-6)


def test_export_svg_refuses_below_the_floor_and_before_too_many_points(tmp_path):
    sec = _section()  # a circle of radius 2: 2 pi sqrt(2 / (8 tol)) chords
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: 1e-300 is below the floor 5.6"):
        sm.export_svg(sec, tmp_path / "s.svg", tolerance=1e-300)
    # 1e-10 is above the floor but needs ~310,000 points (GCPnts: 4 s; 1e-11: 20 s)
    with pytest.raises(sm.SurfmodError, match=r"^tolerance: 1e-10 would need about 31\d,\d\d\d points"):
        sm.export_svg(sec, tmp_path / "s.svg", tolerance=1e-10)
    assert sm.export_svg(sec, tmp_path / "s.svg", tolerance=1e-5) == 1


def test_the_chord_estimate_is_the_count_gcpnts_gives():
    """The estimate that refuses a tolerance up front is the count OCCT then makes, to 5 %."""
    from surfmod.uses.section import chord_points

    sec = _section()
    for tol in (1e-4, 1e-6, 1e-8):
        got = sum(len(p) for p in sec.polylines_2d(tol))
        assert chord_points(sec.polylines, tol) == pytest.approx(got, rel=0.05 if tol < 1e-5 else 0.5)
        assert np.allclose(np.linalg.norm(sec.polylines_2d(tol)[0], axis=1), 2.0, atol=1.01 * tol)
