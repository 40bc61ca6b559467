"""Every bad input of the foundation issue: a SurfmodError (ValueError) naming the argument."""

from __future__ import annotations

import re

import numpy as np
import pytest

import surfmod as sm
from surfmod.checks import step_file

NET = np.random.default_rng(0).uniform(-1, 1, (5, 4, 3))


def test_error_is_a_value_error():
    assert issubclass(sm.SurfmodError, ValueError)
    assert issubclass(sm.KernelError, sm.SurfmodError)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(control_points=np.zeros((5, 4))), r"control_points: expected an array with 3 axes"),
        (dict(control_points=np.zeros((5, 4, 2))), r"control_points: last axis must have length 3"),
        (dict(control_points=np.zeros((1, 4, 3))), r"control_points: need at least 2 x 2"),
        (dict(control_points=np.where(np.eye(5, 4)[..., None] > 0, np.nan, NET)), r"control_points: contains NaN"),
        (dict(control_points=np.full((5, 4, 3), np.inf)), r"control_points: contains NaN or infinite"),
        (dict(control_points="abc"), r"control_points: expected numbers"),
        (dict(degree=(0, 2)), r"degree\[0\] \(u\): must be >= 1"),
        (dict(degree=(5, 2)), r"degree\[0\] \(u\): degree 5 needs at least 6 control points"),
        (dict(degree=(2, 2.5)), r"degree\[1\] \(v\): expected an integer"),
        (dict(degree=3), r"degree: expected a pair"),
        (dict(knots=([0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1])), r"knots\[0\] \(U\): expected 8 knots"),
        (dict(knots=([0, 0, 0, 0.7, 0.3, 1, 1, 1], [0, 0, 0, 1, 1, 1, 1])), r"knots\[0\] \(U\): must be non-decreasing"),
        (dict(knots=([0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 1, 1, 1, 1])), r"knots\[0\] \(U\): multiplicity 4 .* exceeds degree \+ 1"),
        (dict(knots=([0, 0, 0, 0.5, 0.5, 1, 1, 1], [0, 0, 0.5, 0.5, 0.5, 1, 1])), r"knots\[1\] \(V\): empty parameter domain"),
        (dict(knots=([0, 0, 0, 0, 0, 0, 0, 0], [0, 0, 0, 1, 1, 1, 1])), r"knots\[0\] \(U\): multiplicity 8|empty"),
        (dict(knots=([0, 0, 0, np.nan, 1, 1, 1, 1], [0, 0, 0, 1, 1, 1, 1])), r"knots\[0\] \(U\): contains NaN"),
        (dict(weights=np.ones((4, 4))), r"weights: expected shape \(5, 4\)"),
        (dict(weights=np.where(np.eye(5, 4) > 0, 0.0, 1.0)), r"weights: all weights must be > 0"),
        (dict(weights=-np.ones((5, 4))), r"weights: all weights must be > 0"),
    ],
)
def test_bspline_surface_bad_input(kwargs, match):
    args = dict(control_points=NET, degree=(2, 2), knots=None, weights=None)
    args.update(kwargs)
    with pytest.raises(sm.SurfmodError, match=match):
        sm.BSplineSurface(**args)


def test_interior_multiplicity_above_degree():
    with pytest.raises(sm.SurfmodError, match=r"knots\[0\] \(U\): interior knot 0.5 has multiplicity above the degree"):
        sm.BSplineSurface(np.zeros((6, 3, 3)), (2, 1), ([0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1], [0, 0, 0.5, 1, 1]))


@pytest.mark.parametrize("u, v, name", [(1.5, 0.5, "u"), (0.5, -0.1, "v"), (np.nan, 0.5, "u"), (0.5, np.inf, "v")])
def test_parameters_outside_the_domain(u, v, name):
    s = sm.BSplineSurface(NET, (2, 2))
    with pytest.raises(sm.SurfmodError, match=f"^{name}: "):
        s.points(u, v)


def test_grid_parameters_outside_the_domain():
    s = sm.BSplineSurface(NET, (2, 2))
    with pytest.raises(sm.SurfmodError, match="us: parameters must lie in"):
        s.grid([0, 2], [0.5])


def test_curve_bad_input():
    with pytest.raises(sm.SurfmodError, match="points: expected an array with 2 axes"):
        sm.BSplineCurve(np.zeros(3), 1)
    with pytest.raises(sm.SurfmodError, match="degree: degree 4 needs at least 5"):
        sm.BSplineCurve(np.zeros((3, 3)), 4)
    with pytest.raises(sm.SurfmodError, match="weights: all weights must be > 0"):
        sm.BezierCurve(np.zeros((3, 3)), [1, 0, 1])
    with pytest.raises(sm.SurfmodError, match="t: parameters must lie in"):
        sm.BezierCurve(np.eye(3)).points(1.2)


def test_order_and_counts():
    s = sm.BSplineSurface(NET, (2, 2))
    with pytest.raises(sm.SurfmodError, match="order: must be >= 0"):
        s.derivatives(0.5, 0.5, -1)
    with pytest.raises(sm.SurfmodError, match="m: must be >= 2"):
        sm.mesh(s, 1, 4)
    with pytest.raises(sm.SurfmodError, match="samples: must be >= 2"):
        sm.crosscheck(s, samples=1)


def test_transform_bad_input():
    s = sm.BSplineSurface(NET, (2, 2))
    with pytest.raises(sm.SurfmodError, match="matrix: expected a 4x4"):
        s.transformed(np.eye(3))
    with pytest.raises(sm.SurfmodError, match="matrix: linear part is singular"):
        s.transformed(np.diag([1.0, 0.0, 1.0, 1.0]))
    with pytest.raises(sm.SurfmodError, match="axis_direction: zero-length"):
        s.rotated((0, 0, 0), (0, 0, 0), 10)
    with pytest.raises(sm.SurfmodError, match="factor: scale factors must be non-zero"):
        s.scaled(0.0)


def test_inputs_are_copied_and_frozen():
    net = NET.copy()
    s = sm.BSplineSurface(net, (2, 2))
    net[0, 0, 0] = 99.0
    assert s.control_points[0, 0, 0] != 99.0
    with pytest.raises(ValueError):
        s.control_points[0, 0, 0] = 1.0


STEP_TEXT = ("ISO-10303-21;\nHEADER;\nFILE_NAME('a,inf,b /* x */','',(''),(''),'','','');\nENDSEC;\nDATA;\n"
             "#1=CARTESIAN_POINT('it''s,nan,here',(0.,{x},1.E69));\n/* (1.,inf,2.) */\nENDSEC;\nEND-ISO-10303-21;\n")


@pytest.mark.parametrize("x", ["nan", "-INF", "Infinity", "1.#QNAN", "1.E70000", "-1.E308", "9.9E307", " 2.E71 "])
def test_step_text_with_numbers_out_of_range_is_refused_before_occt(tmp_path, x):
    # OCCT 8.0's reader loops on such a control point; the text is refused before it reads
    path = tmp_path / "p.step"
    path.write_text(STEP_TEXT.format(x=x))
    with pytest.raises(sm.DamagedFileError, match=rf"^path: .*p\.step has a number that is NaN, infinite or beyond "
                                                  rf"1e\+70 \('{re.escape(x.strip())}' at byte \d+\)$"):
        step_file(path)


@pytest.mark.parametrize("x", ["1.E70", "-1.E69", "0.", "1.E-400", "7.E07"])
def test_step_text_in_range_passes_even_with_inf_in_strings_and_comments(tmp_path, x):
    path = tmp_path / "p.step"
    path.write_text(STEP_TEXT.format(x=x))
    assert step_file(path) == path
