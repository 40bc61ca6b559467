"""Gallery entries for the swept, lofted and fitted surfaces (issue 4, part B): the four
swept surfaces, smooth and ruled lofts, superellipsoids, an explicit surface and the
interpolation / approximation surfaces."""

from __future__ import annotations

import numpy as np

from ..construct.fitting import approximate, interpolate
from ..construct.forms import explicit
from ..construct.loft import loft
from ..construct.superellipsoid import superellipsoid
from ..construct.sweep import sweep
from ..nets.bspline import BSplineCurve
from . import entry


def _path():
    return BSplineCurve([(0, 0, 0), (0, 0, 20), (15, 5, 40), (40, 0, 45), (50, 15, 60)], 3)


def _profile():
    # an open, asymmetric profile in the plane z = 0 (normal to the path at its start)
    return BSplineCurve([(-5, -5, 0), (0, -7.5, 0), (5, -5, 0), (7.5, 0, 0), (5, 5, 0)], 3)


def _end_profile(mode):
    base = sweep(_profile(), _path(), mode=mode)
    r = base.frames(np.array([0.0, 1.0]))
    p = _path().points(np.array([0.0, 1.0]))
    m = np.eye(4)
    m[:3, :3] = 0.5 * r[1] @ r[0].T
    m[:3, 3] = p[1] - m[:3, :3] @ p[0]
    return _profile().transformed(m)


@entry("sweep_frenet", "swept surface (Frenet frame)", "sm.sweep(profile, path)")
def _sweep_frenet():
    return sweep(_profile(), _path(), mode="frenet")


@entry("sweep_rmf", "swept surface (corrected Frenet)", "sm.sweep(profile, path, mode='corrected_frenet')")
def _sweep_rmf():
    return sweep(_profile(), _path(), mode="corrected_frenet")


@entry("sweep_changing", "swept surface, changing profile", "sm.sweep(a, path, end_profile=b)")
def _sweep_changing():
    return sweep(_profile(), _path(), mode="frenet", end_profile=_end_profile("frenet"))


@entry("sweep_guide", "swept surface with a guide rail", "sm.sweep(profile, path, guide=rail)")
def _sweep_guide():
    rail = BSplineCurve([(0, 10, 0), (0, 12, 20), (15, 15, 40), (40, 5, 45), (50, 20, 60)], 3)
    return sweep(_profile(), _path(), guide=rail)


@entry("sweep_guide_scaled", "swept surface scaled to a guide rail", "sm.sweep(profile, path, guide=rail, guide_scale=True)")
def _sweep_guide_scaled():
    rail = BSplineCurve([(0, 10, 0), (0, 16, 20), (15, 20, 40), (40, 6, 45), (50, 25, 60)], 3)
    return sweep(_profile(), _path(), guide=rail, guide_scale=True)


@entry("sweep_twisted", "twisted swept surface", "sm.sweep(profile, path, twist=180)")
def _sweep_twisted():
    return sweep(_profile(), _path(), mode="corrected_frenet", twist=180.0)


def _sections():
    return [
        BSplineCurve([(0, 0, 0), (10, 10, 0), (20, 0, 0), (30, 5, 0)], 3),
        BSplineCurve([(0, 0, 15), (10, -10, 15), (20, 0, 15)], 2),
        BSplineCurve([(0, 5, 30), (10, 10, 35), (20, 0, 30), (30, 10, 30), (40, 0, 30)], 3),
        BSplineCurve([(0, 0, 45), (40, 0, 45)], 1),
    ]


@entry("loft", "lofted surface (smooth)", "sm.loft(sections)")
def _loft():
    return loft(_sections())


@entry("loft_ruled", "lofted surface (ruled)", "sm.loft(sections, ruled=True)")
def _loft_ruled():
    return loft(_sections()[:2], ruled=True)


@entry("superellipsoid_sharp", "superellipsoid (sharp, s = 0.1)", "sm.superellipsoid(20, 15, 10, 0.1, 0.1)")
def _superellipsoid_sharp():
    return superellipsoid(20, 15, 10, 0.1, 0.1)


@entry("superellipsoid_pinched", "superellipsoid (pinched, s = 3)", "sm.superellipsoid(20, 15, 10, 3, 3)")
def _superellipsoid_pinched():
    # near its cusp edges Su x Sv nearly vanishes and the normals of any two evaluators
    # agree only to ~1e-7; crosscheck weighs normals by that conditioning
    return superellipsoid(20, 15, 10, 3.0, 3.0)


@entry("explicit", "explicit surface z = f(x, y)", "sm.explicit(f, x_range, y_range)")
def _explicit():
    return explicit(lambda x, y: 8 * np.sin(x / 8) * np.cos(y / 6) + 0.1 * x, (0, 50), (0, 40), tolerance=1e-3)


def _scan(n, m):
    x, y = np.meshgrid(np.linspace(0, 50, n), np.linspace(0, 40, m), indexing="ij")
    z = 6 * np.exp(-((x - 25) ** 2 + (y - 20) ** 2) / 150) + 0.05 * x * np.sin(y / 7)
    return np.stack([x + 0.02 * y**2, y, z], axis=-1)


@entry("interpolate", "interpolation surface", "sm.interpolate(points, (3, 3))")
def _interpolate():
    return interpolate(_scan(12, 10))


@entry("approximate", "approximation surface", "sm.approximate(points, (3, 3), tolerance)")
def _approximate():
    return approximate(_scan(40, 30), tolerance=0.01)
