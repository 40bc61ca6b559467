"""Fitting measured points: ``sm.fit`` (scattered, tolerance-driven) beside OCCT's
``GeomAPI_PointsToBSplineSurface`` (grids only), OCCT's ``GeomPlate`` with point
constraints, and scipy's ``SmoothBivariateSpline`` / ``RBFInterpolator`` (height fields).

Every surface's deviation is measured the same way, over every data point: the distance
to OCCT surfaces by OCCT point projection (``GeomAPI_ProjectPointOnSurf``; for
``sm.fit`` its own OCCT-measured ``max_deviation``), the vertical residual for scipy's
height-field functions (an upper bound of the distance).  "poles" counts control points
(``SmoothBivariateSpline``: coefficients; RBF: centres).

``python -m benchmarks fit``            (``--large`` adds a 10^6-point run of sm.fit)
"""

from __future__ import annotations

import sys
import time

import numpy as np

import surfmod as sm

from .tables import Table


def wave(x, y):
    return 0.3 * np.sin(3 * x) * np.cos(2 * y)


def _occt_deviation(geom, pts):
    from surfmod.occ.sample import distances_to_surface

    d = distances_to_surface(geom, pts, geom.Bounds())
    return float(np.nanmax(d)), float(np.sqrt(np.nanmean(d ** 2)))


def _poles(geom):
    return f"{geom.NbUPoles()}x{geom.NbVPoles()}"


TABLE = Table(("data", 26), ("method", 42, "<"), ("max dev", 9), ("rms", 9), ("poles", 9), ("time s", 7), left_first=True)


def _row(name, method, dev, rms, poles, seconds):
    TABLE.row(name, method, f"{dev:.2e}", f"{rms:.2e}", f"{poles}", f"{seconds:.2f}")


def _ours(name, pts, tol, **kw):
    t = time.perf_counter()
    f = sm.fit(pts, tol, **kw)
    n, m = f.surface.control_points.shape[:2]
    _row(name, f"sm.fit tol {tol:g}" + ("" if f.converged else " (limit)"), f.max_deviation, f.rms, f"{n}x{m}",
         time.perf_counter() - t)
    return f


def _scipy(name, pts, tol):
    from scipy.interpolate import RBFInterpolator, SmoothBivariateSpline

    x, y, z = pts.T
    import warnings

    t = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        spl = SmoothBivariateSpline(x, y, z, kx=3, ky=3, s=len(z) * (tol / 3) ** 2)
    res = np.abs(spl.ev(x, y) - z)
    tx, ty = spl.get_knots()
    note = " (FITPACK warned)" if caught else ""
    _row(name, "scipy SmoothBivariateSpline" + note, res.max(), np.sqrt(np.mean(res ** 2)),
         f"{(len(tx) - 4) * (len(ty) - 4)}", time.perf_counter() - t)
    sub = pts[:: max(1, len(pts) // 3000)]  # RBF is dense: O(N^3) in its centres
    t = time.perf_counter()
    rbf = RBFInterpolator(sub[:, :2], sub[:, 2], neighbors=64, kernel="thin_plate_spline", smoothing=0.0)
    res = np.abs(rbf(pts[:, :2]) - z)
    _row(name, f"scipy RBFInterpolator ({len(sub)} ctrs)", res.max(), np.sqrt(np.mean(res ** 2)), f"{len(sub)}",
         time.perf_counter() - t)


def _plate(name, pts, tol):
    from twins.plate import plate_through_points

    sub = pts[:: max(1, len(pts) // 400)]  # GeomPlate solves a dense system per point constraint
    t = time.perf_counter()
    geom = plate_through_points(sub, tolerance=tol)
    dev, rms = _occt_deviation(geom, pts)
    _row(name, f"OCCT GeomPlate ({len(sub)} pt constraints)", dev, rms, _poles(geom), time.perf_counter() - t)


def main(argv=()) -> None:
    TABLE.header()
    rng = np.random.default_rng(0)
    tol = 1e-3
    # 1. a 60 x 60 grid of the wave: OCCT's grid fit applies
    gx, gy = np.meshgrid(np.linspace(-1, 1, 60), np.linspace(-1, 1, 60), indexing="ij")
    grid = np.stack([gx, gy, wave(gx, gy)], -1)
    pts = grid.reshape(-1, 3)
    _ours("wave, 60x60 grid", pts, tol)
    from surfmod.occ.points_to_bspline import points_to_bspline_surface

    t = time.perf_counter()
    geom = points_to_bspline_surface(grid, (3, 3), tol, interpolate=False)
    dev, rms = _occt_deviation(geom, pts)
    _row("wave, 60x60 grid", f"OCCT PointsToBSplineSurface tol {tol:g}", dev, rms, _poles(geom), time.perf_counter() - t)
    # 2. 20 000 scattered points of the wave
    xy = rng.uniform(-1, 1, (20_000, 2))
    pts = np.column_stack([xy, wave(*xy.T)])
    _ours("wave, 20k scattered", pts, tol)
    _plate("wave, 20k scattered", pts, tol)
    _scipy("wave, 20k scattered", pts, tol)
    # 3. the same with a hole of radius 0.5 (fairing keeps the fill calm)
    holed = pts[np.hypot(pts[:, 0], pts[:, 1]) > 0.5]
    _ours("wave with a hole", holed, tol)
    _scipy("wave with a hole", holed, tol)
    # 4. a noisy sphere cap (sigma 1e-3, radius 10)
    d = rng.normal(size=(40_000, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    d = d[d[:, 2] > 0.6][:10_000]
    cap = d * (10 + rng.normal(0, 1e-3, (len(d), 1)))
    _ours("sphere cap, sigma 1e-3", cap, 5e-3)
    _plate("sphere cap, sigma 1e-3", cap, 5e-3)
    _scipy("sphere cap, sigma 1e-3", cap, 5e-3)
    if "--large" in argv or "large" in argv:
        xy = rng.uniform(-1, 1, (1_000_000, 2))
        _ours("wave, 10^6 scattered", np.column_stack([xy, wave(*xy.T)]), tol)


if __name__ == "__main__":
    main(sys.argv[1:])
