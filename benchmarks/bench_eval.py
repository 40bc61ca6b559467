"""Evaluation speed (issue 12): surfmod's local-support evaluation vs OCCT per point,
splipy and geomdl, on nets of 4 to 1000 poles per direction.

Every timing runs twice, in two subprocesses: *1 core* with BLAS and numba pinned to one
thread (``OMP/OPENBLAS/MKL/NUMBA_NUM_THREADS=1``; OCCT's per-point loop is single-threaded
anyway) and *all cores* with the machine's defaults, where work of 2^16 points or more
runs in the parallel kernel variants (:mod:`surfmod.eval.parallel`) on every core.  Single-core times are CPU times of
the process (``time.process_time``), best of several runs, so that other load on a shared
machine inflates neither side (best of 15 for both sides, since the machine is shared);
all-core times are wall times.  OCCT per-point rates
(``Value`` = positions, ``D2`` = all partials to order 2, into preallocated ``gp_Pnt`` /
``gp_Vec``, no conversion) are measured on 100² points through OCP and scaled to the point
count.  The memory-write floor is the time to allocate and fill the output array
("fresh"), or to fill an array that already exists ("reused"), and, for comparison, a
compiled loop that only writes every double of the reused array; the "into" rows write
into a preallocated array with ``BSplineSurface.grid_into`` (as OCCT's side writes into
preallocated points), the others allocate their result.

Start-up (issue 23) is measured in fresh processes (:func:`cold_start`): the README's
first example (a 5x4 net: ``grid``, ``points``, ``derivatives``, ``normals``,
``curvatures``, import included) with ``NUMBA_CACHE_DIR`` pointed at an empty folder and
again with the cache that run filled, and the first against the second call of
``tessellate``, ``project`` and ``mass_properties`` in one process.

``python -m benchmarks eval``
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net

from .tables import Table, heading, note

NET_SIZES = (4, 20, 100, 400, 1000)
GRID = 1000
SCATTERED = 10**6
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


def _clock(single: bool):
    return time.process_time if single else time.perf_counter


def _time(fn, single: bool, repeat: int = 15) -> float:
    clock = _clock(single)
    best = np.inf
    for _ in range(repeat):
        t = clock()
        fn()
        best = min(best, clock() - t)
    return best


def nurbs(n: int, rational: bool = True, degree: int = 3) -> sm.BSplineSurface:
    rng = np.random.default_rng(7)
    w = 10 ** rng.uniform(-1, 1, (n, n)) if rational else None
    return sm.BSplineSurface(wavy_net(n, n), (min(degree, n - 1),) * 2, weights=w)


def occt_rates(s, n: int = 100):
    """CPU seconds per point of ``Value`` and ``D2`` through OCP."""
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

    return _time(d0, True) / n**2, _time(d2, True) / n**2


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


def write_floor(shape, single: bool) -> float:
    """Allocate and fill an array of the output's shape: no evaluator can do less."""
    return _time(lambda: np.empty(shape).fill(0.0), single, 5)


def _write_every(out):
    flat = out.reshape(-1)
    for i in range(flat.size):
        flat[i] = i


def numba_write_floor():
    """A compiled loop that only writes every double of an array (the value of its
    index): the memory-write floor as a kernel sees it, to set beside NumPy's ``fill``."""
    from numba import njit

    return njit(_write_every)


def measure(single: bool) -> dict:
    """Every timing of the tables, in seconds, for this process's thread setting."""
    out = {"net": {}, "rows": {}}
    grid = np.linspace(0, 1, GRID)
    from surfmod.eval.threads import threads_for

    out["threads"] = threads_for(GRID**2)
    buf = np.zeros((GRID, GRID, 3))  # faulted in once, reused by every "into" timing
    for n in NET_SIZES:
        s = nurbs(n)
        s.grid(grid[:10], grid[:10])  # compile / load the kernels outside the timing
        entry = {"ours": _time(lambda: s.grid(grid, grid), single),
                 "into": _time(lambda: s.grid_into(grid, grid, buf), single)}
        sp = splipy_fn(s)
        entry["splipy"] = _time(lambda: sp(grid, grid), single, 2) if sp else None
        if single:
            entry["occt_d0"], entry["occt_d2"] = occt_rates(s)
        out["net"][n] = entry
    rows = out["rows"]
    s20, b20 = nurbs(20), nurbs(20, rational=False)
    rows["grid_poly20"] = _time(lambda: b20.grid(grid, grid), single)
    rows["grid_poly20_into"] = _time(lambda: b20.grid_into(grid, grid, buf), single)
    rows["floor_d0"] = write_floor((GRID, GRID, 3), single)
    rows["floor_d0_reused"] = _time(lambda: buf.fill(0.0), single, 5)
    s20.grid_derivatives(grid[:4], grid[:4], 2)
    rows["grid_d2"] = _time(lambda: s20.grid_derivatives(grid, grid, 2), single)
    rows["grid_d2_poly"] = _time(lambda: b20.grid_derivatives(grid, grid, 2), single)
    rows["floor_d2"] = write_floor((GRID, GRID, 3, 3, 3), single)
    buf2 = np.zeros((GRID, GRID, 3, 3, 3))
    rows["grid_d2_into"] = _time(lambda: s20.grid_into(grid, grid, buf2, order=2), single)
    rows["grid_d2_poly_into"] = _time(lambda: b20.grid_into(grid, grid, buf2, order=2), single)
    rows["floor_d2_reused"] = _time(lambda: buf2.fill(0.0), single, 5)
    write = numba_write_floor()
    write(buf2[:1])
    rows["floor_d2_numba"] = _time(lambda: write(buf2), single, 5)
    rows["floor_d0_numba"] = _time(lambda: write(buf), single, 5)
    del buf2
    rng = np.random.default_rng(3)
    u, v = rng.uniform(0, 1, SCATTERED), rng.uniform(0, 1, SCATTERED)
    s20.derivatives(u[:4], v[:4], 2)
    rows["scattered_d0"] = _time(lambda: s20.points(u, v), single)
    rows["scattered_d2"] = _time(lambda: s20.derivatives(u, v, 2), single, 2)
    for n in (4, 20):
        gd = geomdl_fn(nurbs(n, rational=False))
        small = np.linspace(0, 1, 100)
        rows[f"geomdl{n}"] = _time(lambda: gd(small, small), single, 1) * (GRID / 100) ** 2 if gd else None
        bn = nurbs(n, rational=False)
        rows[f"poly{n}"] = _time(lambda: bn.grid(grid, grid), single)
        if single:
            rows[f"occt_poly{n}"] = occt_rates(bn)[0]
    if single:
        rows["numpy"] = numpy_paths(grid, u, v)
        rows["memory"] = memory()
    return out


def numpy_paths(grid, u, v) -> dict:
    """The NumPy local-support paths (:mod:`surfmod.eval.scattered`, :mod:`surfmod.eval.tensor_grid`, which small work
    takes), timed on the large cases the compiled kernels take, for comparison."""
    from surfmod.eval.scattered import scattered
    from surfmod.eval.tensor_grid import tensor_grid

    res = {}
    for n in (20, 400):
        net = nurbs(n)._local_net()
        res[f"grid{n}"] = _time(lambda: tensor_grid(*net[:4], net.ctrl, True, grid, grid, 0), True, 2)
    net = nurbs(20)._local_net()
    res["scattered"] = _time(lambda: scattered(*net[:4], net.ctrl, True, u, v, 0), True, 1)
    return res


def memory(grid_n: int = 10_000, scattered_n: int = 10**7, chunk: int = 1 << 20) -> dict:
    """A 10^8-point grid (``grid_chunks``) and 10^7 scattered points (in slices) of the
    20x20 NURBS, reduced to a bounding box: time and tracemalloc peak (NumPy reports its
    buffers to tracemalloc; the kernels allocate nothing sizeable themselves)."""
    s = nurbs(20)
    res = {}
    us = vs = np.linspace(0, 1, grid_n)
    tracemalloc.start()
    t = time.process_time()
    lo = np.full(3, np.inf)
    for _, block in s.grid_chunks(us, vs, max_points=1 << 21):
        lo = np.minimum(lo, block.reshape(-1, 3).min(axis=0))
    res["grid"] = (grid_n**2, time.process_time() - t, tracemalloc.get_traced_memory()[1] / 2**20, grid_n**2 * 24 / 2**20)
    tracemalloc.stop()
    rng = np.random.default_rng(5)
    u, v = rng.uniform(0, 1, scattered_n), rng.uniform(0, 1, scattered_n)  # the input itself: 153 MiB
    tracemalloc.start()
    t = time.process_time()
    lo = np.full(3, np.inf)
    for a in range(0, scattered_n, chunk):
        lo = np.minimum(lo, s.points(u[a : a + chunk], v[a : a + chunk]).min(axis=0))
    res["scattered"] = (scattered_n, time.process_time() - t, tracemalloc.get_traced_memory()[1] / 2**20,
                        scattered_n * 24 / 2**20)
    tracemalloc.stop()
    return res


#: the README's first example, in a fresh process: seconds from before the import to the end
README_FIRST = """
import time
t0 = time.perf_counter()
import numpy as np, surfmod as sm
x, y = np.meshgrid(np.linspace(0, 30, 5), np.linspace(0, 20, 4), indexing="ij")
net = np.stack([x, y, 3 * np.sin(x / 8) * np.cos(y / 6)], axis=-1)
s = sm.BSplineSurface(net, degree=(3, 2), weights=np.ones((5, 4)))
u, v = np.linspace(0, 1, 200), np.linspace(0, 1, 100)
s.grid(u, v)
s.points(0.3, 0.6)
s.derivatives(0.3, 0.6, 2)
s.normals(u[:50], v[:50])
s.curvatures(u[:50], v[:50])
print(time.perf_counter() - t0)
"""

#: first and second call of a process (two different objects, so nothing is reused)
FIRST_SECOND = """
import sys, time
import numpy as np, surfmod as sm, build123d as bd
from surfmod.gallery.synthetic import wavy_net
rng = np.random.default_rng(1)
pts = np.c_[rng.uniform(0, 10, 500), rng.uniform(0, 8, 500), rng.uniform(-1, 2, 500)]
calls = {
    "tessellate": lambda k: sm.tessellate(sm.BSplineSurface(wavy_net(8, 8, 0.6 - 0.1 * k), (3, 3)), 0.05),
    "project": lambda k: sm.project(pts, sm.BSplineSurface(wavy_net(8, 8, 0.6 - 0.1 * k), (3, 3)), progress=False),
    "mass_properties": lambda k: sm.mass_properties(bd.Sphere(1 + k) - bd.Box(1, 1, 1)),
}
times = []
for k in range(2):
    t = time.perf_counter()
    calls[sys.argv[1]](k)
    times.append(time.perf_counter() - t)
print(*times)
"""


#: a 96-face corpus part (planes, cylinders, cones, tori, B-splines) for the command's start-up row
MESH_PART = Path(__file__).resolve().parent.parent / "tests" / "data" / "step" / "trimesh_featuretype.STEP"

#: the kernel alone, in a fresh process: OCP imported, the STEP file read, BRepMesh at the
#: command's default deflection, the STL written
OCCT_MESH = """
import sys, time
t0 = time.perf_counter()
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.StlAPI import StlAPI_Writer
from OCP.STEPControl import STEPControl_Reader
reader = STEPControl_Reader()
reader.ReadFile(sys.argv[1])
reader.TransferRoots()
shape = reader.OneShape()
BRepMesh_IncrementalMesh(shape, 0.01, False, 0.5, False)
StlAPI_Writer().Write(shape, sys.argv[2])
print(time.perf_counter() - t0)
"""

#: the command in a fresh process, timed from before its import to its exit
SURFMOD_MESH = """
import sys, time
t0 = time.perf_counter()
from surfmod.cli import main
main(["mesh", sys.argv[1], "--out", sys.argv[2], "--no-progress"])
print(time.perf_counter() - t0)
"""


def _fresh(script: str, cache: str, *args) -> list[float]:
    """Run ``script`` in a fresh one-core process with numba's cache in ``cache``; its
    last line of output as floats."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    for var in THREAD_VARS:
        env[var] = "1"
    done = subprocess.run([sys.executable, "-c", script, *args], env=env, capture_output=True, text=True, check=True)
    return [float(x) for x in done.stdout.strip().splitlines()[-1].split()]


def cold_start() -> dict:
    """Start-up costs in fresh processes (wall seconds, one core): the README's first
    example into an empty numba cache and then with that cache filled; the first and
    second call of tessellate, project and mass_properties, cold and warm."""
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        out["readme_cold"] = _fresh(README_FIRST, cache)[0]
        out["readme_warm"] = min(_fresh(README_FIRST, cache)[0] for _ in range(3))
        for name in ("tessellate", "project", "mass_properties"):
            out[f"{name}_cold"] = _fresh(FIRST_SECOND, cache, name)
            out[f"{name}_warm"] = min(_fresh(FIRST_SECOND, cache, name) for _ in range(2))
        stl = os.path.join(cache, "part.stl")
        out["mesh_surfmod"] = min(_fresh(SURFMOD_MESH, cache, str(MESH_PART), stl)[0] for _ in range(3))
        out["mesh_occt"] = min(_fresh(OCCT_MESH, cache, str(MESH_PART), stl)[0] for _ in range(3))
    return out


def report_cold_start(r: dict) -> None:
    heading("start-up in fresh processes (wall seconds, 1 core; the targets of issues 23 and 34)")
    table = Table(("case", 44, "<"), ("first", 8), ("second", 8), ("first - second", 15), ("target", 24, "<"))
    table.header()
    table.row("README first example, empty numba cache", f"{r['readme_cold']:.2f}", "—", "—", "<= 5 s")
    table.row("README first example, warm cache", f"{r['readme_warm']:.2f}", "—", "—", "<= 1 s, import included")
    for name in ("tessellate", "project", "mass_properties"):
        for kind in ("cold", "warm"):
            first, second = r[f"{name}_{kind}"]
            table.row(f"{name}, {'empty' if kind == 'cold' else 'warm'} cache", f"{first:.3f}", f"{second:.3f}",
                      f"{first - second:+.3f}", "<= +0.3 s" if kind == "warm" else "<= +0.5 s")
    note()
    table = Table(("command in a fresh process (warm cache)", 44, "<"), ("seconds", 8), ("ratio", 8), ("target", 24, "<"))
    table.header()
    table.row("surfmod mesh of a 96-face part", f"{r['mesh_surfmod']:.2f}", f"{r['mesh_surfmod'] / r['mesh_occt']:.2f}",
              "<= 2 x the kernel alone")
    table.row("OCP alone: read, BRepMesh, STL", f"{r['mesh_occt']:.2f}", "1.00", "")
    note("README example: import, a 200x100 grid, points, derivatives, normals, curvatures of a 5x4 net;")
    note("tessellate: a wavy 8x8 NURBS at 0.05; project: 500 points on it; mass_properties: sphere minus box;")
    note("surfmod mesh: trimesh_featuretype.STEP at its default 0.01, the STL read back and judged; the best of 3.")
    note()


def _run_worker(single: bool) -> dict:
    env = dict(os.environ)
    for var in THREAD_VARS:
        if single:
            env[var] = "1"
        else:
            env.pop(var, None)
    cmd = [sys.executable, "-m", "benchmarks.bench_eval", "--worker", "single" if single else "all"]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def _f(x, spec=".4f", unit="s"):
    return "—" if x is None else f"{x:{spec}}{unit}"


def _x(a, b):
    return "—" if a is None or b is None or b == 0 else f"{a / b:.1f}x"


def report(one: dict, every: dict) -> None:
    note(f"threads of the compiled kernels: 1c {one['threads']}, all {every['threads']} "
         f"(parallel variants, equal bit for bit; the machine has {os.cpu_count()} cores)")
    note()
    heading(f"{GRID}² grid of positions, rational bicubic net n x n (OCCT: per-point Value x 10^6)")
    table = Table(("net", 9), ("surfmod 1c", 11), ("into 1c", 8), ("surfmod all", 12), ("OCCT", 7), ("splipy 1c", 10),
                  ("splipy all", 11), ("x OCCT", 7), ("into", 7), ("x splipy 1c", 12), ("x splipy all", 13))
    table.header()
    for n in map(str, NET_SIZES):
        a, b = one["net"][n], every["net"][n]
        occ = a["occt_d0"] * GRID**2
        table.row(n + "x" + n, _f(a["ours"]), _f(a["into"]), _f(b["ours"]), _f(occ, ".3f"), _f(a["splipy"]),
                  _f(b["splipy"]), _x(occ, a["ours"]), _x(occ, a["into"]), _x(a["splipy"], a["ours"]),
                  _x(b["splipy"], b["ours"]))
    note("into = BSplineSurface.grid_into, writing into a preallocated array (x OCCT of that column)")
    r, ra = one["rows"], every["rows"]
    d0_20, d2_20 = one["net"]["20"]["occt_d0"], one["net"]["20"]["occt_d2"]
    note()
    table = Table(("case (20x20 bicubic unless named)", 40), ("surfmod 1c", 11), ("surfmod all", 12), ("OCCT", 11),
                  ("x OCCT", 10), ("floor", 8), ("x floor", 8), left_first=True)
    table.header()
    lines = [
        ("1000² grid, rational NURBS", one["net"]["20"]["ours"], every["net"]["20"]["ours"], d0_20 * GRID**2, r["floor_d0"]),
        ("  into a preallocated array", one["net"]["20"]["into"], every["net"]["20"]["into"], d0_20 * GRID**2,
         r["floor_d0_reused"]),
        ("1000² grid, polynomial B-spline", r["grid_poly20"], ra["grid_poly20"], r["occt_poly20"] * GRID**2, r["floor_d0"]),
        ("  into a preallocated array", r["grid_poly20_into"], ra["grid_poly20_into"], r["occt_poly20"] * GRID**2,
         r["floor_d0_reused"]),
        ("1000² grid, 4x4 polynomial", r["poly4"], ra["poly4"], r["occt_poly4"] * GRID**2, r["floor_d0"]),
        ("1000² grid, partials to 2, NURBS", r["grid_d2"], ra["grid_d2"], d2_20 * GRID**2, r["floor_d2"]),
        ("  into a preallocated array", r["grid_d2_into"], ra["grid_d2_into"], d2_20 * GRID**2, r["floor_d2_reused"]),
        ("1000² grid, partials to 2, B-spline", r["grid_d2_poly"], ra["grid_d2_poly"], d2_20 * GRID**2, r["floor_d2"]),
        ("  into a preallocated array", r["grid_d2_poly_into"], ra["grid_d2_poly_into"], d2_20 * GRID**2,
         r["floor_d2_reused"]),
        ("10⁶ scattered, NURBS positions", r["scattered_d0"], ra["scattered_d0"], d0_20 * SCATTERED, None),
        ("10⁶ scattered, NURBS partials to 2", r["scattered_d2"], ra["scattered_d2"], d2_20 * SCATTERED, None),
    ]
    for name, t1, ta, occ, floor in lines:
        table.row(name, _f(t1), _f(ta), _f(occ, ".3f"), _x(occ, t1), _f(floor), _x(t1, floor))
    note("partials to 2: OCCT D2 gives 6 vectors a point, surfmod the full 3x3 square (27 doubles);")
    note("floor = allocate and fill the output array (for the \"into\" rows: fill the reused array);")
    note("x floor = surfmod / floor (1 = at the floor).")
    note(f"a compiled loop that only writes the reused array: {_f(r['floor_d0_numba'])} (positions), "
         f"{_f(r['floor_d2_numba'])} (partials to 2: {_x(d2_20 * GRID**2, r['floor_d2_numba'])} OCCT D2).")
    note()
    heading("geomdl (pure Python, timed on 100², scaled to 1000²), polynomial bicubic:")
    table = Table(("net", 9), ("geomdl", 9), ("surfmod", 9), ("x geomdl", 10))
    table.header()
    for n in (4, 20):
        table.row(f"{n}x{n}", _f(r[f"geomdl{n}"], ".1f"), _f(r[f"poly{n}"]), _x(r[f"geomdl{n}"], r[f"poly{n}"]))
    npy = r["numpy"]
    note()
    heading("numba kernels vs the NumPy paths of small work (eval/scattered.py, tensor_grid.py; 1 core, rational bicubic):")
    table = Table(("case", 24), ("NumPy", 9), ("numba", 9), ("speed-up", 9), left_first=True)
    table.header()
    table.row("1000² grid, 20x20 net", _f(npy["grid20"]), _f(one["net"]["20"]["ours"]),
              _x(npy["grid20"], one["net"]["20"]["ours"]))
    table.row("1000² grid, 400x400 net", _f(npy["grid400"]), _f(one["net"]["400"]["ours"]),
              _x(npy["grid400"], one["net"]["400"]["ours"]))
    table.row("10⁶ scattered, 20x20", _f(npy["scattered"]), _f(r["scattered_d0"]), _x(npy["scattered"], r["scattered_d0"]))
    note()
    heading("bounded memory (20x20 NURBS, reduced to a bounding box as it streams):")
    for key, what in (("grid", "grid via grid_chunks(max_points=2^21)"), ("scattered", "scattered in slices of 2^20")):
        count, secs, peak, whole = r["memory"][key]
        note(f"  {count:.0e} points, {what}: {secs:.1f} s CPU (bounding box included), tracemalloc peak {peak:.0f} MiB "
             f"(one array of the result: {whole:.0f} MiB)")


def main() -> None:
    report_cold_start(cold_start())
    one, every = _run_worker(True), _run_worker(False)
    report(one, every)


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--worker":
        print(json.dumps(measure(sys.argv[2] == "single")))
    elif sys.argv[1:] == ["--cold"]:  # the start-up rows only
        report_cold_start(cold_start())
    else:
        main()
