"""STEP export/import of surfmod surfaces and build123d shapes (atomic writes)."""

from __future__ import annotations

from ..errors import SurfmodError
from .atomic import atomic_path, target_path


def to_shape(obj):
    """The TopoDS shape of a surfmod surface/curve, build123d object or TopoDS shape."""
    from ..curve import Curve
    from ..surface import Surface

    if isinstance(obj, Surface):
        return obj.face().wrapped
    if isinstance(obj, Curve):
        return obj.edge().wrapped
    shape = getattr(obj, "wrapped", obj)
    if type(shape).__module__.startswith("OCP") and hasattr(shape, "IsNull") and not shape.IsNull():
        return shape
    raise SurfmodError(f"objects: cannot export {type(obj).__name__} (expected surfaces, curves or build123d shapes)")


def _as_list(objects):
    if isinstance(objects, (list, tuple)):
        items = list(objects)
    else:
        items = [objects]
    if not items:
        raise SurfmodError("objects: nothing to export")
    return items


def export_step(objects, path) -> None:
    """Write surfaces, curves or build123d shapes to one AP214 STEP file, atomically.

    >>> import surfmod as sm, tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> sm.export_step(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), os.path.join(d, "p.step"))
    """
    from ..occ.exchange import compound, write_step

    target = target_path(path, "path", (".step", ".stp"))
    shapes = [to_shape(o) for o in _as_list(objects)]
    shape = shapes[0] if len(shapes) == 1 else compound(shapes)
    with atomic_path(target) as tmp:
        write_step(shape, tmp)


def import_step(path):
    """Read a STEP file as a build123d shape (``Compound``/``Solid``/…).

    >>> import surfmod as sm, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "p.step")
    >>> sm.export_step(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), path)
    >>> len(sm.import_step(path).faces())
    1
    """
    import os

    import build123d as bd

    from ..occ.exchange import read_step

    if not os.path.isfile(os.fspath(path)):
        raise SurfmodError(f"path: no such file {path}")
    with open(path, "rb") as fh:
        head = fh.read(64)
    if b"ISO-10303-21" not in head:
        raise SurfmodError(f"path: {path} is not a STEP file (no ISO-10303-21 header)")
    return bd.Compound.cast(read_step(path)) if hasattr(bd.Compound, "cast") else bd.Compound(read_step(path))
