"""Turn whatever the user hands to a "use" into an OCCT shape, and OCCT shapes back into
the build123d objects users get: with :mod:`surfmod.occ`, the only module that imports
build123d.

Accepted: a surfmod ``Surface`` (its face), a list/tuple of surfaces or faces (sewn into
a closed solid when ``solid=True``), any build123d shape, an OCP ``TopoDS_Shape``, or the
path of a STEP file.
"""

from __future__ import annotations

import os

import numpy as np

from .errors import SurfmodError
from .surface import Surface


def load_step(path, name: str = "obj"):
    """The TopoDS shape in a STEP file, read in the isolated reader process
    (:func:`surfmod.import_step`); unreadable or damaged files raise ``SurfmodError``."""
    from .occ.isolated import read_step_file

    return read_step_file(path, name)


def _single(item, name):
    if isinstance(item, Surface):
        return item.face().wrapped
    shape = getattr(item, "wrapped", item)
    if type(shape).__module__.startswith("OCP") and hasattr(shape, "IsNull"):
        if shape.IsNull():
            raise SurfmodError(f"{name}: is an empty shape")
        return shape
    raise SurfmodError(
        f"{name}: expected a surfmod surface, a list of them, a build123d shape or a STEP path, "
        f"got {type(item).__name__}"
    )


def to_shape(obj, name: str = "obj", *, solid: bool = False, outward: bool = True):
    """The OCCT shape for ``obj``; with ``solid=True`` a closed, outward-oriented solid
    (open shells raise ``SurfmodError``); ``outward=False`` leaves turning each solid by
    the sign of its volume to a caller that integrates it anyway
    (:func:`surfmod.occ.solids.closed_solid`)."""
    from .occ.solids import closed_solid, sew_solid

    if isinstance(obj, (str, os.PathLike)):
        shape = load_step(obj, name)
    elif isinstance(obj, (list, tuple)):
        if not obj:
            raise SurfmodError(f"{name}: empty list of surfaces")
        faces = [_single(o, name) for o in obj]
        if solid:
            return sew_solid(faces)
        from .occ.topo import compound

        shape = compound(faces)
    else:
        shape = _single(obj, name)
    if solid:
        try:
            return closed_solid(shape, outward)
        except SurfmodError as exc:
            msg = str(exc)
            raise SurfmodError(msg if msg.startswith(name) else f"{name}: {msg}") from None
    return shape


def make_solid(surfaces):
    """A build123d ``Solid`` bounded by surfmod surfaces (and/or faces) that close up:
    they are sewn (``BRepBuilderAPI_Sewing``) and oriented outwards.  Faces that leave
    free edges raise ``SurfmodError``.

    >>> import surfmod as sm, build123d as bd
    >>> cube = sm.make_solid(bd.Box(1, 2, 3).faces())
    >>> round(cube.volume, 12)
    6.0
    """
    import build123d as bd

    if not isinstance(surfaces, (list, tuple)) or not surfaces:
        raise SurfmodError("surfaces: expected a non-empty list of surfaces or faces")
    return bd.Solid(to_shape(list(surfaces), "surfaces", solid=True))


def upright_cylinder(base, radius: float, height: float):
    """A build123d solid cylinder standing on ``base`` (the centre of its bottom) along +Z
    (a tool's holder, :mod:`surfmod.cam.holder`)."""
    import build123d as bd

    bottom = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)
    return bd.Pos(*map(float, base)) * bd.Cylinder(float(radius), float(height), align=bottom)


def build123d_face(shape):
    """The build123d ``Face`` of a ``TopoDS_Face``."""
    import build123d as bd

    return bd.Face(shape)


def build123d_shell(shape):
    """The build123d ``Shell`` of a ``TopoDS_Shell``."""
    import build123d as bd

    return bd.Shell(shape)


def build123d_compound(objects):
    """A build123d ``Compound`` of a list of build123d objects, or the build123d object
    of one ``TopoDS_Shape`` read from a file (build123d's ``cast`` picks its class).

    >>> import surfmod as sm
    >>> len(build123d_compound([sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)).face()]).faces())
    1
    """
    import build123d as bd

    if isinstance(objects, list):
        return bd.Compound(objects)
    return bd.Compound.cast(objects) if hasattr(bd.Compound, "cast") else bd.Compound(objects)


def edge_positions(edge, ts) -> np.ndarray:
    """Points ``(len(ts), 3)`` of a build123d ``Edge``/``Wire`` at normalized parameters
    ``ts`` in ``[0, 1]`` (build123d's ``PositionMode.PARAMETER``)."""
    from build123d import PositionMode

    return np.array([tuple(edge.position_at(t, PositionMode.PARAMETER)) for t in ts])
