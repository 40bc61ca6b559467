"""Explicit, implicit and parametric forms and the conversions between them."""

import numpy as np
import pytest

import surfmod as sm


def f_wave(x, y):
    return np.sin(x) * np.cos(y) + 0.1 * x * y


def test_explicit_fit_within_tolerance_and_linear_xy():
    s = sm.explicit(f_wave, (0, 3), (-1, 2), tolerance=1e-6)
    assert s.max_deviation <= 1e-6
    rng = np.random.default_rng(1)
    x, y = rng.uniform(0, 3, 400), rng.uniform(-1, 2, 400)
    p = s.points(x, y)
    assert np.abs(p[:, 0] - x).max() < 1e-13 and np.abs(p[:, 1] - y).max() < 1e-13
    assert np.abs(p[:, 2] - f_wave(x, y)).max() <= 1e-6
    assert sm.crosscheck(s, samples=16).passed


def test_explicit_default_tolerance_and_forms():
    s = sm.explicit(lambda x, y: np.exp(-4 * (x**2 + y**2)), (-1, 1), (-1, 1))
    assert s.tolerance == pytest.approx(2e-3) and s.max_deviation <= s.tolerance
    # explicit -> parametric is exact, explicit -> implicit z - f is zero on the exact form
    xy = np.array([[0.3, -0.2], [0.0, 0.9]])
    exact = s.parametric(xy[:, 0], xy[:, 1])
    F = sm.to_implicit(s)
    assert np.abs(F.value(exact)).max() < 1e-15
    assert np.abs(F.value(s.points(xy[:, 0], xy[:, 1]))).max() <= s.tolerance
    # the implicit normal of z - f is (-fx, -fy, 1)/|.|, the parametric normal the same
    n_imp = F.normals(exact)
    n_par = s.normals(xy[:, 0], xy[:, 1])
    assert np.abs(n_imp - n_par).max() < 5e-3


def test_explicit_nan_is_refused():
    with pytest.raises(sm.SurfmodError, match=r"f: returned nan .* at \(x, y\)"):
        sm.explicit(lambda x, y: np.sqrt(x) * y, (-1, 1), (0, 1))
    with pytest.raises(sm.SurfmodError, match="f: raised ZeroDivisionError"):
        sm.explicit(lambda x, y: 1 / 0, (0, 1), (0, 1))
    with pytest.raises(sm.SurfmodError, match="x_range"):
        sm.explicit(f_wave, (1, 1), (0, 1))
    with pytest.raises(sm.SurfmodError, match="f: expected a callable"):
        sm.explicit(3.0, (0, 1), (0, 1))
    with pytest.raises(sm.SurfmodError, match="tolerance"):
        sm.explicit(f_wave, (0, 1), (0, 1), tolerance=0)


def test_implicit_gradient_numeric_matches_analytic():
    F = lambda x, y, z: x**2 / 4 + y**2 + z**2 / 9 - 1
    grad = lambda x, y, z: (x / 2, 2 * y, 2 * z / 9)
    a = sm.implicit(F, gradient=grad)
    n = sm.implicit(F, bounds=((-2, 2), (-1, 1), (-3, 3)))
    assert a.analytic_gradient and not n.analytic_gradient
    rng = np.random.default_rng(2)
    p = rng.normal(size=(50, 3))
    assert np.abs(a.gradient(p) - n.gradient(p)).max() < 1e-8
    on = a.project(p)
    assert np.abs(a.value(on)).max() < 1e-12
    assert np.allclose(np.linalg.norm(a.normals(p), axis=-1), 1.0, atol=1e-15)


def test_plane_to_implicit_is_signed_distance():
    pl = sm.plane((0, 0, 0), (2, 0, 0), (0, 0, 3))
    F = sm.to_implicit(pl)
    p = np.array([[1.0, 2.5, 0.3], [0.0, -1.0, 4.0]])
    assert np.allclose(F.value(p), pl.implicit(p), atol=1e-15)
    assert np.allclose(np.abs(F.distance_estimate(p)), [2.5, 1.0], atol=1e-9)


def test_implicit_bad_inputs():
    with pytest.raises(sm.SurfmodError, match="F: expected a callable"):
        sm.implicit(1.0)
    with pytest.raises(sm.SurfmodError, match="bounds"):
        sm.implicit(lambda x, y, z: x, bounds=((0, 1), (0, 1)))
    cone = sm.implicit(lambda x, y, z: x**2 + y**2 - z**2, gradient=lambda x, y, z: (2 * x, 2 * y, -2 * z))
    with pytest.raises(sm.SurfmodError, match="xyz: the gradient vanishes"):
        cone.normals((0.0, 0.0, 0.0))
    with pytest.raises(sm.SurfmodError, match="surface: no implicit form"):
        sm.to_implicit(sm.BSplineSurface(np.random.default_rng(0).normal(size=(4, 4, 3))))


def test_quadric_parametric_to_implicit():
    s = sm.sphere(2.0)
    F = sm.to_implicit(s)
    (u0, u1), (v0, v1) = s.domain
    u, v = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0 + 0.1, v1 - 0.1, 7))
    p = s.points(u, v)
    assert np.abs(F.value(p)).max() < 1e-12
    n_imp, n_par = F.normals(p), s.normals(u, v)
    assert np.abs(np.abs(np.sum(n_imp * n_par, axis=-1)) - 1).max() < 1e-8


def test_implicit_to_explicit_where_it_exists():
    ball = sm.implicit(lambda x, y, z: x**2 + y**2 + z**2 - 4, gradient=lambda x, y, z: (2 * x, 2 * y, 2 * z))
    cap = ball.to_explicit((-1, 1), (-1, 1), z0=2.0, tolerance=1e-7)
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-1, 1, 300), rng.uniform(-1, 1, 300)
    assert np.abs(cap.points(x, y)[:, 2] - np.sqrt(4 - x**2 - y**2)).max() <= 1e-7
    lower = ball.to_explicit((-1, 1), (-1, 1), z0=-2.0, tolerance=1e-6)
    assert lower.points(0.0, 0.0)[2] == pytest.approx(-2.0, abs=1e-12)
    # the equator sheet x^2 + y^2 = 4 has dF/dz = 0 at z = 0
    with pytest.raises(sm.SurfmodError, match="z0: dF/dz vanishes"):
        ball.to_explicit((-1, 1), (-1, 1), z0=0.0)
