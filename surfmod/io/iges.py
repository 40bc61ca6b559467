"""IGES export/import of surfmod surfaces and build123d shapes (atomic writes), beside
STEP (:mod:`surfmod.io.step`).  B-spline and NURBS surfaces travel as IGES entity 128
with their degrees, knots, weights and poles unchanged.

The same concept as :mod:`surfmod.occ.iges`: this is the user's door (atomic writes, checks), that the OCCT reader/writer.
"""

from __future__ import annotations

import os

from ..errors import SurfmodError
from ..atomic import atomic_path, target_path
from .step import _as_list, to_shape

SUFFIXES = (".igs", ".iges")


def export_iges(objects, path, *, brep: bool = False) -> None:
    """Write surfaces, curves or build123d shapes to one IGES file, atomically.

    ``brep=True`` writes solids as IGES B-rep (entity 186) instead of trimmed surfaces.

    >>> import surfmod as sm, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "p.igs")
    >>> sm.export_iges(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), path)
    >>> len(sm.import_iges(path).faces())
    1
    """
    from ..occ.topo import compound
    from ..occ.iges import write_iges

    target = target_path(path, "path", SUFFIXES)
    shapes = [to_shape(o) for o in _as_list(objects)]
    shape = shapes[0] if len(shapes) == 1 else compound(shapes)
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
    import build123d as bd

    from ..occ.iges import read_iges

    if not os.path.isfile(os.fspath(path)):
        raise SurfmodError(f"path: no such file {path}")
    with open(path, "rb") as fh:
        head = fh.read(81)
    # IGES: fixed 80-column records, the Start section flagged by 'S' in column 73
    if len(head) < 73 or head[72:73] != b"S":
        raise SurfmodError(f"path: {path} is not an IGES file (no Start section record)")
    shape = read_iges(path)
    return bd.Compound.cast(shape) if hasattr(bd.Compound, "cast") else bd.Compound(shape)
