"""STEP and IGES export/import of surfmod surfaces and build123d shapes (atomic writes):
the public doors over OCCT's readers and writers (:mod:`surfmod.occ.step`,
:mod:`surfmod.occ.iges`).  In IGES, B-spline and NURBS surfaces travel as entity 128
with their degrees, knots, weights and poles unchanged.  :func:`shape_changes` says
what a write and read changed of a shape (the round-trip check of ``export_step`` and
``surfmod convert --check``).
"""

from __future__ import annotations

import os
import warnings

import numpy as np

from ..curve import Curve
from ..errors import InsideOutWarning, RoundTripWarning, SurfmodError
from ..atomic import atomic_path, target_path
from ..inputs import build123d_compound, read_step_file
from ..surface import Surface


def _export_shape(obj):
    """The TopoDS shape of a surfmod surface/curve, build123d object or TopoDS shape."""
    if isinstance(obj, Surface):
        return obj.face().wrapped
    if isinstance(obj, Curve):
        return obj.edge().wrapped
    shape = getattr(obj, "wrapped", obj)
    if type(shape).__module__.startswith("OCP") and hasattr(shape, "IsNull") and not shape.IsNull():
        return shape
    raise SurfmodError(f"objects: cannot export {type(obj).__name__} (expected surfaces, curves or build123d shapes)")


def _exported(objects):
    """The one TopoDS shape to write: the shape of one object, a compound of several."""
    from ..occ.topo import compound

    items = list(objects) if isinstance(objects, (list, tuple)) else [objects]
    if not items:
        raise SurfmodError("objects: nothing to export")
    shapes = [_export_shape(o) for o in items]
    return shapes[0] if len(shapes) == 1 else compound(shapes)


def export_step(objects, path, *, strict: bool = False) -> None:
    """Write surfaces, curves or build123d shapes to one AP214 STEP file, atomically, and
    read it back to check that it holds what was given.

    The file keeps every face, shell and solid as given (a solid's REVERSED shell is
    written as its faces reversed; reals with 17 digits; the file's uncertainty is the
    shape's greatest tolerance, so OCCT's reader finds nothing to heal).  The written file
    is then read back (in the isolated reader of :func:`import_step`) and compared with
    the objects: the number of solids, of faces and of faces in no solid, and each
    solid's face count, orientation (the sign of its enclosed volume), volume and
    centroid to 1e-12 relative.  Where the file does not give that back (a solid whose
    shell is open comes back as a shell; on a few real parts OCCT's reader re-projects
    p-curves), a :class:`~surfmod.errors.RoundTripWarning` names the solids or faces and
    the size of the change; ``strict=True`` raises :class:`~surfmod.errors.SurfmodError`
    instead and writes nothing.

    >>> import surfmod as sm, tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> sm.export_step(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), os.path.join(d, "p.step"))
    """
    from ..occ.step import write_step

    target = target_path(path, "path", (".step", ".stp"))
    shape = _exported(objects)
    with atomic_path(target) as tmp:
        write_step(shape, tmp)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", InsideOutWarning)  # an orientation change is one of the changes
            again = read_step_file(tmp, "path")
        changes = shape_changes(shape, again)
        if changes:
            said = "; ".join(changes[:10]) + (f"; and {len(changes) - 10} more" if len(changes) > 10 else "")
            message = f"{target.name} read back differs from the objects written: {said}"
            if strict:
                raise SurfmodError(f"objects: {message} (strict=True writes nothing)")
            warnings.warn(message, RoundTripWarning, stacklevel=2)


def import_step(path, *, timeout: float | None = None, max_coordinate: float = 1e9):
    """Read a STEP file as a build123d shape (``Compound``/``Solid``/…).

    The file is read in a separate, reused worker process with a time limit, so a damaged
    file that crashes or hangs OCCT's reader raises :class:`~surfmod.errors.DamagedFileError`
    naming the file instead of taking the caller down.  ``timeout`` (seconds) defaults to
    30 s plus 10 s per megabyte; a shape with NaN coordinates or coordinates beyond
    ``max_coordinate`` (model units) is refused the same way.

    >>> import surfmod as sm, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "p.step")
    >>> sm.export_step(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), path)
    >>> len(sm.import_step(path).faces())
    1
    >>> with open(path, "r+b") as fh:     # cut the file short
    ...     _ = fh.truncate(600)
    >>> try:
    ...     sm.import_step(path)
    ... except sm.DamagedFileError as exc:
    ...     print("p.step" in str(exc))
    True
    """
    return build123d_compound(read_step_file(path, "path", timeout=timeout, max_coordinate=max_coordinate))


#: the file suffixes of IGES
IGES_SUFFIXES = (".igs", ".iges")


def export_iges(objects, path, *, brep: bool = False) -> None:
    """Write surfaces, curves or build123d shapes to one IGES file, atomically.

    ``brep=True`` writes solids as IGES B-rep (entity 186) instead of trimmed surfaces.

    >>> import surfmod as sm, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "p.igs")
    >>> sm.export_iges(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), path)
    >>> len(sm.import_iges(path).faces())
    1
    """
    from ..occ.iges import write_iges

    target = target_path(path, "path", IGES_SUFFIXES)
    shape = _exported(objects)
    with atomic_path(target) as tmp:
        write_iges(shape, tmp, brep=bool(brep))


def import_iges(path):
    """Read an IGES file as a build123d shape (``Compound``/``Solid``/...); its faces go
    back to surfmod with :func:`surfmod.from_face`.

    >>> import surfmod as sm, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "p.iges")
    >>> sm.export_iges(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), path)
    >>> type(sm.from_face(sm.import_iges(path).faces()[0]).surface).__name__
    'BSplineSurface'
    """
    from ..occ.iges import read_iges

    if not os.path.isfile(os.fspath(path)):
        raise SurfmodError(f"path: no such file {path}")
    with open(path, "rb") as fh:
        head = fh.read(81)
    # IGES: fixed 80-column records, the Start section flagged by 'S' in column 73
    if len(head) < 73 or head[72:73] != b"S":
        raise SurfmodError(f"path: {path} is not an IGES file (no Start section record)")
    return build123d_compound(read_iges(path))


def shape_changes(given, again, rtol: float = 1e-12) -> list[str]:
    """What a write and read (``again``) changed of ``given``, one line per change: the
    number of solids, of faces and of faces in no solid (loose faces, open shells); each
    solid's face count, the sign of its enclosed volume, its volume (relative) and its
    centroid (relative to the volume's cube root) beyond ``rtol``, each loose face's area
    and centroid alike.  Solids and faces pair in the explorer's order (numbered from 1).

    >>> import build123d as bd
    >>> box = bd.Solid.make_box(1, 2, 3).wrapped
    >>> shape_changes(box, box)
    []
    >>> shape_changes(box, bd.Solid.make_box(1, 2, 3.3).wrapped)
    ['solid 1: volume 6 -> 6.6 (relative change 0.1); centroid moved 0.15 (0.0825 of the volume^(1/3))']
    >>> shape_changes(box, box.Reversed())
    ['solid 1: enclosed volume 6 -> -6 (turned inside out)']
    """
    from ..occ.properties import solid_figures
    from ..occ.topo import faces_of, loose_faces, solids_of

    changes = []
    a, b = solids_of(given), solids_of(again)
    fa, fb = len(faces_of(given)), len(faces_of(again))
    loose_a, loose_b = loose_faces(given), loose_faces(again)
    if len(a) != len(b):
        changes.append(f"solids: {len(a)} -> {len(b)}")
    if fa != fb:
        changes.append(f"faces: {fa} -> {fb}")
    if len(loose_a) != len(loose_b):
        changes.append(f"faces in no solid: {len(loose_a)} -> {len(loose_b)}")
    for i, (x, y) in enumerate(zip(loose_a, loose_b) if len(loose_a) == len(loose_b) else (), 1):
        changes += _moved(f"face {i} in no solid", "area", 2, solid_figures(x), solid_figures(y), rtol)
    for i, (x, y) in enumerate(zip(a, b), 1):
        nx, ny = len(faces_of(x)), len(faces_of(y))
        if nx != ny:
            changes.append(f"solid {i}: faces {nx} -> {ny}")
            continue
        (va, ca), (vb, cb) = solid_figures(x), solid_figures(y)
        if (va < 0) != (vb < 0):
            changes.append(f"solid {i}: enclosed volume {va:.6g} -> {vb:.6g} (turned "
                           f"{'inside out' if vb < 0 else 'outward'})")
            continue
        changes += _moved(f"solid {i}", "volume", 3, (va, ca), (vb, cb), rtol)
    return changes


def _moved(name: str, measure: str, root: int, before, after, rtol: float) -> list[str]:
    """``[line]`` if ``(measure, centroid)`` moved beyond ``rtol`` (centroid over the measure's ``root``-th root)."""
    (ma, ca), (mb, cb) = before, after
    size = max(abs(ma), 1e-300)
    dm, dc, scale = abs(mb - ma) / size, float(np.abs(cb - ca).max()), size ** (1 / root)
    if dm > rtol or dc > rtol * scale:
        return [f"{name}: {measure} {ma:.6g} -> {mb:.6g} (relative change {dm:.3g}); "
                f"centroid moved {dc:.3g} ({dc / scale:.3g} of the {measure}^(1/{root}))"]
    return []
