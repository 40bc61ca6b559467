"""Surfaces and curves are values: public attributes bind once, arrays are read-only,
and the OCCT twin is built once and cached."""

from __future__ import annotations

import numpy as np
import pytest

import surfmod as sm
from surfmod.immutable import ImmutableError

NET = np.stack([*np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij"), np.zeros((4, 3))], axis=-1)


def _values():
    arc = sm.Arc((0, 0, 0), (0, 0, 1), 2.0, 0.0, 90.0)
    return [
        (sm.BSplineSurface(NET, (2, 1)), "control_points"),
        (sm.BezierSurface(NET), "weights"),
        (sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), "knots"),
        (sm.sphere(2.0), "origin"),
        (sm.ellipsoid(1, 2, 3), "radii"),
        (sm.tabulated_cylinder(arc, (0, 0, 1), 3.0), "direction"),
        (sm.revolution(sm.Line((1, 0, 0), (2, 0, 3)), (0, 0, 0), (0, 0, 1), 180.0), "profile"),
        (sm.explicit(lambda x, y: x * y, (0, 1), (0, 1), 1e-3), "max_deviation"),
        (sm.BSplineCurve(NET[:, 0], 2), "degree"),
        (arc, "x_dir"),
    ]


@pytest.mark.parametrize("value, name", _values(), ids=lambda x: x if isinstance(x, str) else type(x).__name__)
def test_public_attributes_cannot_be_rebound(value, name):
    before = getattr(value, name)
    with pytest.raises(ImmutableError, match=rf"^{name}: .* is immutable"):
        setattr(value, name, before)
    with pytest.raises(AttributeError):
        delattr(value, name)
    assert getattr(value, name) is before


def test_immutable_error_is_a_surfmod_error_and_an_attribute_error():
    assert issubclass(ImmutableError, sm.SurfmodError) and issubclass(ImmutableError, AttributeError)


def test_rebinding_the_net_cannot_leave_a_stale_evaluation():
    s = sm.BSplineSurface(NET, (2, 1))
    p = s.points(0.5, 0.5)
    with pytest.raises(ImmutableError):
        s.control_points = NET * 2
    with pytest.raises(ValueError, match="read-only"):
        s.control_points[0, 0, 0] = 7.0
    np.testing.assert_array_equal(s.points(0.5, 0.5), p)


@pytest.mark.parametrize("value", [sm.sphere(1.0), sm.tabulated_cylinder(sm.Line((0, 0, 0), (1, 0, 0)), (0, 0, 1), 2.0)])
def test_occt_twin_is_built_once(value):
    assert value.geom() is value.geom()


def test_transforms_make_new_values():
    s = sm.BSplineSurface(NET, (2, 1))
    t = s.translated((1, 2, 3))
    assert t is not s
    np.testing.assert_allclose(t.control_points, NET + [1, 2, 3], rtol=0, atol=0)
    np.testing.assert_array_equal(s.control_points, NET)
