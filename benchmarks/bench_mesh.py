"""Meshing: surfmod's tessellation vs OCCT's BRepMesh on the same faces at the same
tolerance -- triangle count, *measured* max deviation and wall time for both.

Both meshes are measured the same way: 25 sample points per triangle (edges and
interior), each projected onto the exact surface by Gauss-Newton from its
parameter-space correspondent (closed-form distance for OCCT's analytic surfaces).
BRepMesh is run with ``deflection = tolerance`` and its default angular deflection 0.5;
its deflection is not a guarantee, so the table also shows BRepMesh with the deflection
tightened until its measured deviation is within the tolerance ("BRepMesh ok"): that is
the fair "equal measured deviation" count.  Solids go through surfmod's BRepMesh path,
which does that tightening itself and checks watertightness.

Times are wall clock, best of ``REPEAT`` runs, one core: surfmod's ``sm.tessellate``
(verification included, after one warm-up call per surface so that numba's compiled
kernels are loaded) and OCCT's ``BRepMesh_IncrementalMesh`` call alone (triangulation
cleared before each run; reading the triangulation back and measuring it are not
counted), once at ``deflection = tol`` and once at the tightened deflection of
"BRepMesh ok".  ``time ratio`` is surfmod's time over BRepMesh's at ``deflection = tol``.

``python -m benchmarks.bench_mesh [NAME ...] [--no-solids]`` (NAME: part of a surface's
name, to run only those rows)
"""

from __future__ import annotations

import time

import numpy as np

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.meshing.brep import DENSE, measure_face_meshes
from surfmod.meshing.facemesh import brepmesh

from .tables import Table, note


def _nurbs_sphere(r: float = 5.0):
    s2 = np.sqrt(0.5)
    cu = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], float)
    wu = np.array([1, s2, 1, s2, 1, s2, 1, s2, 1])
    cv = np.array([[0, -1], [1, -1], [1, 0], [1, 1], [0, 1]], float)
    wv = np.array([1, s2, 1, s2, 1])
    net = np.array([[[r * a * c, r * b * c, r * d] for c, d in cv] for a, b in cu])
    ku = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
    kv = [0, 0, 0, 0.5, 0.5, 1, 1, 1]
    return sm.BSplineSurface(net, (2, 2), (ku, kv), np.outer(wu, wv))


def surfaces():
    ku = [0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1]
    kv = [0, 0, 0, 0.3, 0.6, 1, 1, 1]
    w = np.ones((6, 6))
    w[2:4, 2:4] = 4.0
    w[0, :] = 0.5
    return {
        "Bezier 6x5 (wavy)": sm.BezierSurface(wavy_net(6, 5)),
        "B-spline (3,2) non-uniform": sm.BSplineSurface(wavy_net(7, 5), (3, 2), (ku, kv)),
        "NURBS 6x6 weighted": sm.BSplineSurface(wavy_net(6, 6), (3, 3), weights=w),
        "NURBS sphere r=5": _nurbs_sphere(5.0),
        "sphere r=5 (Geom_Spherical)": sm.sphere(5.0),
        "torus 8/2 (Geom_Toroidal)": sm.torus(8.0, 2.0),
    }


#: timed runs per measurement (the best is kept)
REPEAT = 2


def _sphere_distance(points, r: float = 5.0):
    return np.abs(np.linalg.norm(points, axis=-1) - r)


#: closed-form distances for B-spline faces whose geometry has one (the NURBS sphere is
#: an exact sphere): the same measurement as a projection, without hours of Gauss-Newton
#: on BRepMesh's 300,000-triangle meshes
CLOSED_FORM = {"NURBS sphere r=5": _sphere_distance}


def _brep(face, tol, closed_form=None):
    fms = brepmesh(face, tol)
    n = sum(len(f.triangles) for f in fms)
    if closed_form is not None:
        samples = [np.einsum("kj,tjd->tkd", DENSE, f.nodes[f.triangles]) for f in fms]
        return n, float(max(closed_form(q).max() for q in samples))
    return n, float(measure_face_meshes(fms, DENSE).max())


def _brep_time(face, deflection) -> float:
    """Wall time of ``BRepMesh_IncrementalMesh`` alone (best of ``REPEAT``)."""
    from OCP.BRepMesh import BRepMesh_IncrementalMesh

    from surfmod.occ.mesh import clean

    shape = face.wrapped
    best = np.inf
    for _ in range(REPEAT):
        clean(shape)
        t = time.perf_counter()
        BRepMesh_IncrementalMesh(shape, float(deflection), False, 0.5, False)
        best = min(best, time.perf_counter() - t)
    clean(shape)
    return best


def _brep_ok(face, tol, closed_form=None):
    """BRepMesh with the deflection tightened until its measured deviation is <= tol:
    ``(triangles, deviation, deflection)``."""
    d = tol
    for _ in range(12):
        n, dev = _brep(face, d, closed_form)
        if dev <= tol:
            return n, dev, d
        d *= max(0.3, 0.95 * tol / dev)
    return n, dev, d


def _ours(s, tol):
    best, m = np.inf, None
    for _ in range(REPEAT):
        t = time.perf_counter()
        m = sm.tessellate(s, tol)
        best = min(best, time.perf_counter() - t)
    return m, best


def rows(tolerances=(0.01, 0.001), only=()):
    """One tuple per surface and tolerance, yielded as soon as it is measured; ``only``:
    substrings of the surface names to run (all when empty)."""
    for name, s in surfaces().items():
        if only and not any(o in name for o in only):
            continue
        face = s.face()
        closed_form = CLOSED_FORM.get(name)
        sm.tessellate(s, 0.1)  # warm-up: numba kernels loaded from the cache
        for tol in tolerances:
            m, dt = _ours(s, tol)
            n_b, dev_b = _brep(face, tol, closed_form)
            t_b = _brep_time(face, tol)
            n_ok, dev_ok, d_ok = _brep_ok(face, tol, closed_form)
            t_ok = _brep_time(face, d_ok)
            yield name, tol, len(m.faces), m.info["max_deviation"], dt, n_b, dev_b, t_b, n_ok, dev_ok, t_ok


def solid_rows(tolerances=(0.01, 0.001)):
    import build123d as bd

    hole = bd.Solid.make_cylinder(2, 10).moved(bd.Location((5, 5, 0)))
    solids = {
        "filleted box - hole": bd.fillet(bd.Solid.make_box(10, 10, 10).edges(), 1.5) - hole,
        "torus solid 8/2": bd.Solid.make_torus(8, 2),
    }
    out = []
    for name, solid in solids.items():
        for tol in tolerances:
            t = time.perf_counter()
            m = sm.tessellate(solid, tol)
            dt = time.perf_counter() - t
            tm = m.to_trimesh()
            n_b, dev_b = _brep(solid, tol)
            ok = tm.is_watertight and tm.is_winding_consistent
            out.append((name, tol, len(m.faces), m.info["max_deviation"], dt, n_b, dev_b, ok))
    return out


def main(only=(), solids: bool = True) -> None:
    """Print the tables (``only``: substrings of surface names; ``solids``: the solid
    table too)."""
    table = Table(("surface", 28), ("tol", 6), ("ours tris", 9), ("ours dev", 9), ("ours s", 7), ("BRepMesh tris", 13),
                  ("BRepMesh dev", 12), ("BRepMesh s", 10), ("BRepMesh ok tris", 16), ("ok dev", 9), ("ok s", 7),
                  ("ours/ok tris", 12), ("time ratio", 10), left_first=True)
    table.header()
    for name, tol, n, dev, dt, n_b, dev_b, t_b, n_ok, dev_ok, t_ok in rows(only=only):
        flag = "" if dev_b <= tol else " (!)"
        table.row(name, f"{tol:g}", f"{n:d}", f"{dev:.3g}", f"{dt:.3f}", f"{n_b:d}", f"{dev_b:.3g}{flag}", f"{t_b:.3f}",
                  f"{n_ok:d}", f"{dev_ok:.3g}", f"{t_ok:.3f}", f"{n / n_ok:.2f}", f"{dt / t_b:.2f}")
    note("(!) BRepMesh's measured deviation exceeds the requested deflection")
    note()
    if not solids:
        return
    table = Table(("solid", 22), ("tol", 6), ("tris", 7), ("measured dev", 12), ("time s", 6),
                  ("BRepMesh(defl=tol) tris", 23), ("its dev", 9), ("watertight", 10), left_first=True)
    table.header()
    for name, tol, n, dev, dt, n_b, dev_b, ok in solid_rows():
        table.row(name, f"{tol:g}", f"{n:d}", f"{dev:.3g}", f"{dt:.2f}", f"{n_b:d}", f"{dev_b:.3g}", "yes" if ok else "NO")


if __name__ == "__main__":
    import sys

    names = [a for a in sys.argv[1:] if a != "--no-solids"]
    main(names, "--no-solids" not in sys.argv[1:])
