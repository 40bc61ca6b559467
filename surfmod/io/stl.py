"""STL export (binary or ASCII) of meshes, surfaces and build123d shapes; atomic."""

from __future__ import annotations

import warnings

import numpy as np

from .. import checks
from ..atomic import atomic_path, target_path
from ..errors import RoundTripWarning, SurfmodError
from ..meshing.closure import STL_RECORD, judge_stl
from ..meshing.polymesh import Mesh
from ..meshing.tessellate import tessellate

#: fractions of the tolerance at which a part whose STL does not close is meshed again
#: (each within the tolerance asked for; about 4x, 16x and 64x the triangles at most).
#: An eighth: where two faces meet at a knife edge (a zero dihedral angle, a propeller's
#: tip), both meshes share the triangles along it until the mesh is fine enough to part them
REMESH = (0.5, 0.25, 0.125)


def _mesh_of(obj, tolerance: float, strict: bool, progress: bool) -> Mesh:
    if isinstance(obj, Mesh):
        return obj.triangulated()
    return tessellate(obj, tolerance, strict=strict, progress=progress)


def merged(meshes: list[Mesh]) -> Mesh:
    verts, faces, offset = [], [], 0
    for m in meshes:
        verts.append(m.vertices)
        faces.append(m.triangles() + offset)
        offset += len(m.vertices)
    # keep what the tessellation measured (e.g. max_deviation) for the caller
    info = dict(meshes[0].info) if len(meshes) == 1 else {}
    devs = [m.info["max_deviation"] for m in meshes if "max_deviation" in m.info]
    if devs:
        info["max_deviation"] = max(devs)
    info["faces_over_tolerance"] = [r for m in meshes for r in m.info.get("faces_over_tolerance", [])]
    info["open_faces"] = sum(m.info.get("open_faces", 0) for m in meshes)
    # what each run of triangles promises (a solid's: to close), in file order; a mesh or
    # a surface promises nothing of the kind
    info["stl_groups"] = [
        (name if name is None or len(meshes) == 1 else f"object {k}, {name}", count, faces)
        for k, m in enumerate(meshes, 1)
        for name, count, faces in m.info.get("stl_groups", [(None, len(m.triangles()), None)])
    ]
    return Mesh(np.concatenate(verts), np.concatenate(faces), info)


def as_written(mesh: Mesh) -> Mesh:
    """``mesh`` as an STL holds it: the triangles whose corners float32 makes equal (the
    file stores float32, and a reader finds them degenerate) are left out, with their
    groups' counts and face labels.  OCCT's test part for its bug 27693 meshes two nodes
    of one face 4e-14 apart: written as they were, the STL held 4 degenerate facets that
    admesh removes.  The mesh in double keeps them (a weld at float32 would move nodes by
    up to half a float32 step and change what gmsh fills).

    >>> m = Mesh(np.array([[0., 0, 0], [1, 0, 0], [1 + 4e-14, 0, 0], [0, 1, 0]]), np.array([[0, 1, 3], [1, 2, 3]]),
    ...          {"stl_groups": [("solid 1", 2, np.array([7, 8]))]})
    >>> w = as_written(m)
    >>> w.triangles().tolist(), w.info["stl_groups"][0][1], w.info["stl_groups"][0][2].tolist()
    ([[0, 1, 3]], 1, [7])
    """
    tri = mesh.triangles()
    c = mesh.vertices.astype(np.float32)[tri]
    gone = (np.all(c[:, 0] == c[:, 1], axis=1) | np.all(c[:, 1] == c[:, 2], axis=1)
            | np.all(c[:, 0] == c[:, 2], axis=1))
    if not gone.any():
        return mesh
    info, groups, start = dict(mesh.info), [], 0
    for name, count, faces in info.get("stl_groups", [(None, len(tri), None)]):
        keep = ~gone[start:start + count]
        groups.append((name, int(keep.sum()), None if faces is None else np.asarray(faces)[keep]))
        start += count
    info["stl_groups"] = groups
    return Mesh(mesh.vertices, tri[~gone], info)


def facet_normals(tri: np.ndarray) -> np.ndarray:
    """Unit normals (float32) of triangles ``(T, 3, 3)`` as an STL reader recomputes and
    checks them: from the vertices rounded to float32 (what the file holds), edge vectors
    in float32, each cross-product term in double with the first rounded to float, the
    length in double (admesh's arithmetic, followed operation by operation).  A needle
    triangle's normal is ill-conditioned, so any other rounding gives another one:
    plain float32 put a sliver of pythonocc_Ventilator.stp 1.4e-3 off (admesh's limit is
    1e-3), plain float64 did so on 36 needles of nist_ctc_04/05, and admesh "fixed" them.

    >>> facet_normals(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]])).tolist()
    [[0.0, 0.0, 1.0]]
    """
    t = np.asarray(tri, dtype=np.float32)
    e1 = (t[:, 1] - t[:, 0]).astype(np.float64)
    e2 = (t[:, 2] - t[:, 0]).astype(np.float64)
    first = (e1[:, [1, 2, 0]] * e2[:, [2, 0, 1]]).astype(np.float32).astype(np.float64)
    n = (first - e1[:, [2, 0, 1]] * e2[:, [1, 2, 0]]).astype(np.float32).astype(np.float64)
    length = np.sqrt((n * n).sum(axis=1, keepdims=True))
    ok = length >= np.float64(np.float32(1e-12))
    return np.where(ok, n / np.where(ok, length, 1.0), 0.0).astype(np.float32)


def write_binary(fh, tri: np.ndarray) -> None:
    record = np.zeros(len(tri), dtype=STL_RECORD)
    record["n"] = facet_normals(tri)
    record["v"] = tri
    header = b"surfmod binary STL".ljust(80, b" ")
    fh.write(header)
    fh.write(np.uint32(len(tri)).tobytes())
    fh.write(record.tobytes())


def write_ascii(fh, tri: np.ndarray, name: str = "surfmod") -> None:
    normals = facet_normals(tri)
    lines = [f"solid {name}"]
    for n, t in zip(normals, tri):
        lines.append(f"  facet normal {n[0]:.9e} {n[1]:.9e} {n[2]:.9e}")
        lines.append("    outer loop")
        lines.extend(f"      vertex {p[0]:.9e} {p[1]:.9e} {p[2]:.9e}" for p in t)
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}\n")
    fh.write("\n".join(lines).encode("ascii"))


def export_stl(objects, path, tolerance: float = 0.01, *, ascii: bool = False, strict: bool = False,
               progress: bool = False) -> Mesh:
    """Write meshes, surfaces or build123d shapes to one STL file, atomically.

    Surfaces and shapes are tessellated with :func:`surfmod.tessellate` so the measured
    chordal deviation stays below ``tolerance``; a closed solid gives a watertight STL.
    Faces of a real part that are themselves off by more than ``tolerance`` (the model's
    own error, within its declared tolerance) are listed in the returned mesh's
    ``info["faces_over_tolerance"]`` (face index, surface type, measured deviation, model
    tolerance); ``strict=True`` refuses them instead and writes nothing.  ``progress``
    shows a tqdm bar while meshing.  Returns the mesh that was written.

    The file written is read back and judged (:mod:`surfmod.meshing.closure`): the
    triangles of every solid whose shells are closed must be closed, 2-manifold,
    consistently and outward oriented, without a degenerate facet (0 admesh repairs).
    Faces in no closed shell promise nothing of the kind (``info["open_faces"]``).  A
    solid that breaks the promise, and a face whose triangles stray from it farther than
    its nodes and its model tolerance explain (a meshing failure, not the model's), are
    listed in ``info["stl_problems"]`` (the solids' verdicts, counts of open,
    non-manifold and inconsistent edges and degenerate facets, in ``info["stl_verdicts"]``
    as ``(name, Closure)``) and said in a
    :class:`~surfmod.errors.RoundTripWarning` naming the solids and faces; ``strict=True``
    raises instead and writes nothing.  Before that, a part with an open or non-manifold
    edge, a degenerate facet or a mis-meshed face is meshed again at the finer
    tolerances of :data:`REMESH` (within ``tolerance`` still); the first mesh that
    passes is written and ``info["remeshed"]`` says why.

    >>> import surfmod as sm, tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> m = sm.export_stl(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), os.path.join(d, "p.stl"))
    >>> len(m.faces) > 0
    True
    """
    tolerance = checks.positive(tolerance, "tolerance")
    target = target_path(path, "path", (".stl",))
    items = list(objects) if isinstance(objects, (list, tuple)) else [objects]
    if not items:
        raise SurfmodError("objects: nothing to export")
    mesh = as_written(merged([_mesh_of(o, tolerance, strict, progress) for o in items]))
    meshed = any(not isinstance(o, Mesh) for o in items)
    with atomic_path(target) as tmp:
        problems, finer_may_close = _written(tmp, mesh, ascii)
        held = mesh  # what the file holds
        # repair: the whole part meshed again, finer (still within ``tolerance``), while
        # a solid is open or a face was mis-meshed; orientation is not the mesh's to fix
        for fraction in REMESH if problems and finer_may_close and meshed else ():
            try:
                finer = as_written(merged([_mesh_of(o, tolerance * fraction, strict, progress) for o in items]))
            except SurfmodError:  # past max_triangles: the first mesh stays, reported
                break
            left, finer_may_close = _written(tmp, finer, ascii)
            held = finer
            if not left:
                finer.info["remeshed"] = (f"{'; '.join(problems)} at tolerance {tolerance:g}: closed meshed again "
                                          f"at {tolerance * fraction:g}")
                mesh, problems = finer, []
                break
            if not finer_may_close:
                break
        if held is not mesh:
            _written(tmp, mesh, ascii)
        if problems and strict:
            raise SurfmodError("objects: the STL read back breaks its promise (strict=True writes nothing): "
                               + "; ".join(problems))
    mesh.info["stl_problems"] = problems
    if problems:
        warnings.warn(f"{target.name} read back breaks its promise: " + "; ".join(problems), RoundTripWarning,
                      stacklevel=2)
    return mesh


def _written(tmp, mesh: Mesh, ascii: bool) -> tuple[list[str], bool]:
    """Write ``mesh`` to ``tmp``, read it back and judge it: the broken promises, one line
    each, and whether a finer mesh may mend them (an open or non-manifold edge, a
    degenerate facet, a face BRepMesh mis-meshed)."""
    with open(tmp, "wb") as fh:
        (write_ascii if ascii else write_binary)(fh, mesh.vertices[mesh.triangles()])
    failing = judge_stl(tmp, mesh.info["stl_groups"])
    mesh.info["stl_verdicts"] = failing  # what a folder run's row says of each file: counts, not only words
    mis_meshed = [r for r in mesh.info["faces_over_tolerance"] if r.get("cause") == "mesh"]
    problems = [f"{name}: {verdict.describe()}" for name, verdict in failing] + [
        f"face {r['face']} ({r['surface']}): triangles {r['deviation']:.3g} off the face while its nodes are "
        f"{r['node_deviation']:.3g} off and its model tolerance is {r['model_tolerance']:.3g}: a meshing failure"
        for r in mis_meshed]
    return problems, bool(mis_meshed) or any(v.open or v.non_manifold or v.degenerate for _, v in failing)
