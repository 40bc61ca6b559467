"""The Curve protocol's derived quantities against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm


def test_polyline_length_is_exact_per_span():
    # Uneven spans: one Gauss rule over the whole domain misses the kinks (0.57 % off).
    pts = np.array([(0, 0, 0), (1, 0, 0), (1, 5, 0), (1.5, 5, 2), (9, 5, 2)], dtype=float)
    exact = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    c = sm.BSplineCurve(pts, 1)
    assert abs(c.length(samples=1) - exact) <= 1e-14 * exact
    assert abs(c.length() - exact) <= 1e-14 * exact


def test_breaks_are_the_distinct_knots_in_the_domain():
    c = sm.BSplineCurve(np.random.default_rng(1).normal(size=(6, 3)), 2, [0, 0, 0, 0.2, 0.2, 0.7, 1, 1, 1])
    np.testing.assert_array_equal(c.breaks, [0, 0.2, 0.7, 1])


def test_circle_length_is_two_pi_r():
    c = sm.Circle((1, 2, 3), (0, 1, 1), 2.5)
    assert abs(c.length() - 2 * np.pi * 2.5) <= 1e-12 * 2 * np.pi * 2.5


def test_length_samples_is_validated():
    with pytest.raises(sm.SurfmodError, match="samples"):
        sm.Line((0, 0, 0), (1, 0, 0)).length(samples=0)
