"""Evaluation speed: surfmod's vectorized grid vs OCCT per-point, splipy and geomdl.

Cases (issue 3): a 20x20 bicubic B-spline, a 20x20 rational bicubic NURBS and a degree-5
Bézier patch, on 100^2, 500^2 and 1000^2 parameter grids.  OCCT per-point rates
(``Value`` = D0, ``D2``) are measured on 100^2 points through OCP and scaled to the grid
size (a 10^6-point Python loop over OCP would only measure the same rate for longer).
Finally a 10^8-point grid is evaluated in chunks, reporting the peak memory.
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net

GRIDS = (100, 500, 1000)


def _time(fn, repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def cases():
    rng = np.random.default_rng(7)
    net = wavy_net(20, 20)
    yield "20x20 bicubic B-spline", sm.BSplineSurface(net, (3, 3))
    yield "20x20 rational NURBS", sm.BSplineSurface(net, (3, 3), weights=10 ** rng.uniform(-1, 1, (20, 20)))
    yield "degree-5 Bezier", sm.BezierSurface(wavy_net(6, 6))


def occt_rates(s, n: int = 100):
    from OCP.gp import gp_Pnt, gp_Vec

    g = s.geom()
    us = np.linspace(*s.domain[0], n).tolist()
    vs = np.linspace(*s.domain[1], n).tolist()

    def d0():
        for u in us:
            for v in vs:
                g.Value(u, v)

    p, vecs = gp_Pnt(), [gp_Vec() for _ in range(5)]

    def d2():
        for u in us:
            for v in vs:
                g.D2(u, v, p, *vecs)

    return _time(d0) / n**2, _time(d2) / n**2


def splipy_fn(s):
    try:
        import splipy
    except ImportError:
        return None
    (p, q), (ku, kv) = s.degree, s.knots
    cp = s.control_points
    if s.rational:  # splipy takes projective points (w x, w y, w z, w)
        w = s.weights[..., None]
        cp = np.concatenate([cp * w, w], axis=-1)
    surf = splipy.Surface(splipy.BSplineBasis(p + 1, ku), splipy.BSplineBasis(q + 1, kv),
                          cp.transpose(1, 0, 2).reshape(-1, cp.shape[-1]), rational=s.rational)
    return lambda us, vs: surf(us, vs)


def geomdl_fn(s):
    try:
        from geomdl import BSpline
    except ImportError:
        return None
    if s.rational:
        return None
    (p, q), (ku, kv) = s.degree, s.knots
    surf = BSpline.Surface()
    surf.degree_u, surf.degree_v = p, q
    n, m = s.control_points.shape[:2]
    surf.ctrlpts_size_u, surf.ctrlpts_size_v = n, m
    surf.ctrlpts = s.control_points.reshape(-1, 3).tolist()
    surf.knotvector_u, surf.knotvector_v = list(ku), list(kv)
    return lambda us, vs: surf.evaluate_list([(u, v) for u in us for v in vs])


def _fmt(x: float, spec: str, unit: str = "") -> str:
    return "—" if x is None or not np.isfinite(x) else f"{x:{spec}}{unit}"


def main() -> None:
    rows = []
    for name, s in cases():
        occ_d0, occ_d2 = occt_rates(s)
        sp, gd = splipy_fn(s), geomdl_fn(s)
        for n in GRIDS:
            us = np.linspace(*s.domain[0], n)
            vs = np.linspace(*s.domain[1], n)
            t_ours = _time(lambda: s.grid(us, vs))
            t_ours_d2 = _time(lambda: s.grid_derivatives(us, vs, 2), 1)
            t_sp = _time(lambda: sp(us, vs)) if sp else None
            t_gd = _time(lambda: gd(us, vs), 1) if gd and n <= 100 else None
            rows.append((name, f"{n}²", t_ours, t_ours_d2, occ_d0 * n * n, occ_d2 * n * n, t_sp, t_gd))
        rows.append(scattered_row(name, s, occ_d0, occ_d2))
    head = (f"{'case':<24} {'points':>8} {'surfmod D0':>11} {'surfmod D2':>11} {'OCCT D0':>9} {'OCCT D2':>9} "
            f"{'x OCCT D0':>10} {'x OCCT D2':>10} {'splipy':>9} {'x splipy':>9} {'geomdl':>8}")
    print(head)
    print("-" * len(head))
    for name, n, t, t2, o0, o2, tsp, tgd in rows:
        print(f"{name:<24} {n:>8} {t:>10.4f}s {t2:>10.4f}s {o0:>8.3f}s {o2:>8.3f}s {o0 / t:>9.0f}x {o2 / t2:>9.0f}x "
              f"{_fmt(tsp, '8.4f', 's'):>9} {_fmt(tsp and tsp / t, '8.2f', 'x'):>9} {_fmt(tgd, '7.3f', 's'):>8}")
    print("D0 = positions, D2 = all partials up to 2 (OCCT D2: 6 vectors per point; surfmod: the")
    print("full 3x3 square of mixed partials).  OCCT times are per-point rates measured on 100²")
    print("points through OCP, times the point count.  x splipy > 1 means surfmod is faster;")
    print("geomdl (pure Python) is timed on 100² only; splipy has no scattered-point evaluation.")
    chunked()


def scattered_row(name, s, occ_d0, occ_d2, n: int = 10**6):
    """Random (u, v) pairs instead of a grid: the path projection and meshing use."""
    rng = np.random.default_rng(3)
    (u0, u1), (v0, v1) = s.domain
    u, v = rng.uniform(u0, u1, n), rng.uniform(v0, v1, n)
    t = _time(lambda: s.points(u, v), 2)
    t2 = _time(lambda: s.derivatives(u, v, 2), 1)
    return name, "1e6 rnd", t, t2, occ_d0 * n, occ_d2 * n, None, None


def chunked(n: int = 10_000) -> None:
    """Evaluate an n x n (10^8 point) grid block by block; report time and peak memory."""
    s = sm.BSplineSurface(wavy_net(20, 20), (3, 3))
    us = np.linspace(0, 1, n)
    vs = np.linspace(0, 1, n)
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    tracemalloc.start()  # NumPy reports its buffers to tracemalloc: this is the array memory
    t = time.perf_counter()
    for _, block in s.grid_chunks(us, vs, max_points=1 << 21):
        flat = block.reshape(-1, 3)
        lo, hi = np.minimum(lo, flat.min(axis=0)), np.maximum(hi, flat.max(axis=0))
    dt = time.perf_counter() - t
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    print(f"\n{n * n:.0e} points in chunks of 2^21: {dt:.1f} s, peak array memory {peak:.0f} MiB "
          f"(a single array would need {n * n * 24 / 2**20:.0f} MiB); bbox {lo.round(3)} .. {hi.round(3)}")


if __name__ == "__main__":
    main()
