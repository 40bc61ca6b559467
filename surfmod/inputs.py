"""Turn whatever the user hands to a "use" into an OCCT shape, and OCCT shapes back into
the build123d objects users get: with :mod:`surfmod.occ`, the only module that imports
build123d.

Accepted: a surfmod ``Surface``, a list of surfaces or faces (sewn into a closed solid when
``solid=True``), any build123d shape, an OCP ``TopoDS_Shape``, or a STEP file's path.
Volume work gets a closed solid whose faces agree and point out (:func:`closed_solid`).  A
STEP file is read in one reused :class:`surfmod.child.Server`, so a file that crashes or
hangs OCCT's reader raises :class:`~surfmod.errors.DamagedFileError` naming it
(:func:`read_step_file`) and the next read starts a fresh child.
See :doc:`/design` (section "The kernel door").
"""

from __future__ import annotations

import atexit
import os
import signal
import threading
import warnings

import numpy as np

from . import checks
from .child import ChildFailure, Server
from .errors import DamagedFileError, InsideOutWarning, SurfmodError
from .occ.isolated import load_occt, read_and_check
from .surface import Surface


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
    (:func:`closed_solid`)."""
    from .occ.solids import sew_solid

    if isinstance(obj, (str, os.PathLike)):
        shape = read_step_file(obj, name)
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


def closed_solid(shape, outward: bool = True):
    """A closed solid (or compound of them) for volume work; open shells are sewn at the
    model's tolerance and refused if they stay open.  Each closed solid's faces are made
    to agree (:func:`oriented_solid`); ``outward=False`` leaves turning a whole solid by
    the sign of its volume to the caller, which integrates that volume anyway and then
    says so as this does (the solids are those of the result, in order)."""
    from .occ.solids import is_closed, loose_faces_solid, solid_of_shell
    from .occ.topo import compound, shells_of, solids_of

    solids = solids_of(shape)
    if solids:
        out = []
        for i, s in enumerate(solids):
            shells = shells_of(s)
            if all(is_closed(sh) for sh in shells):
                # volume work needs faces that agree and point out: turned from the model
                # (shared edges, then the sign of the enclosed volume), never face by face
                oriented, turned, volume = oriented_solid(s, outward)
                if turned:
                    warnings.warn(f"solid {i + 1}: face(s) {', '.join(map(str, turned[:10]))}"
                                  f"{' ...' if len(turned) > 10 else ''} of its shell point against their "
                                  "neighbours: turned to agree with them", InsideOutWarning, stacklevel=3)
                if volume < 0:
                    warnings.warn(f"solid {i + 1} is inside out (enclosed volume {volume:.6g}): turned outward",
                                  InsideOutWarning, stacklevel=3)
                out.append(oriented)
            elif len(shells) == 1:
                out.append(solid_of_shell(shells[0], f"solid {i}"))
            else:
                raise SurfmodError(f"obj: solid {i} has an open shell among {len(shells)} (free edges): "
                                   "volume needs a closed boundary")
        return out[0] if len(out) == 1 else compound(out)
    shells = shells_of(shape)
    if shells:
        out = [solid_of_shell(sh, f"shell {i}") for i, sh in enumerate(shells)]
        return out[0] if len(out) == 1 else compound(out)
    return loose_faces_solid(shape)


def oriented_solid(solid, outward: bool = True):
    """``solid`` with its faces made to agree (:func:`consistent_turns` over the edges
    they share, for a solid of one shell) and then, with ``outward``, turned outward as a
    whole by the sign of its enclosed volume; returns ``(solid, faces turned (positions
    in explorer order), enclosed volume before)``.  ``solid`` itself when nothing needed
    turning.  ``outward=False`` leaves the whole-solid turn to a caller that integrates
    the volume anyway (the mass quadrature, BRepGProp's cross-check), so it is computed
    once: the volume returned is then NaN.

    >>> import build123d as bd
    >>> s, turned, volume = oriented_solid(bd.Solid.make_box(1, 2, 3).wrapped.Reversed())
    >>> turned, round(volume, 12)
    ([], -6.0)
    """
    from .occ.properties import solid_figures
    from .occ.solids import face_links, solid_of_faces
    from .occ.topo import shells_of

    turned: list = []
    if len(shells_of(solid)) == 1:
        faces, links, odd = face_links(solid)
        if odd:
            turned = consistent_turns(sorted(links), {k: 1 for k in range(len(faces))})
        if turned:
            solid = solid_of_faces(face.Reversed() if k in turned else face for k, face in enumerate(faces))
    if not outward:
        return solid, turned, float("nan")
    volume = solid_figures(solid)[0]  # negative when the faces point inwards
    return (solid.Reversed() if volume < 0 else solid), turned, volume


def consistent_turns(links, sizes: dict) -> list:
    """The faces to turn so that no two neighbours disagree: ``links`` are ``(a, b,
    odd)`` for faces ``a`` and ``b`` sharing an edge (``odd`` true where the edge runs the
    same way in both: they disagree), ``sizes`` each face's weight (triangles, or 1).  Of
    the two consistent colourings of each connected set of faces the lighter one turns;
    ``[]`` when no colouring is consistent (a non-orientable or self-contradicting set).

    >>> consistent_turns([(0, 1, 0), (1, 2, 1), (0, 2, 1)], {0: 5, 1: 5, 2: 1})
    [2]
    """
    neighbours: dict = {}
    for a, b, odd in links:
        neighbours.setdefault(a, []).append((b, int(odd)))
        neighbours.setdefault(b, []).append((a, int(odd)))
    colour: dict = {}
    for start in sorted(sizes, key=lambda f: -sizes[f]):  # each connected set from its largest face
        if start in colour:
            continue
        colour[start], todo, part = 0, [start], [start]
        while todo:
            f = todo.pop()
            for g, odd in neighbours.get(f, ()):
                if g not in colour:
                    colour[g] = colour[f] ^ odd
                    todo.append(g)
                    part.append(g)
                elif colour[g] != colour[f] ^ odd:
                    return []
        if sum(sizes[f] for f in part if colour[f]) > sum(sizes[f] for f in part) / 2:
            for f in part:
                colour[f] ^= 1
    return sorted(int(f) for f, c in colour.items() if c)


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


class _Reader:
    """The reader child of this process, one read at a time (a lock: threads share it);
    a forked process starts its own rather than share its parent's."""

    def __init__(self) -> None:
        self.server = Server(warmup=(load_occt, ()))
        self.owner = os.getpid()
        self.lock = threading.Lock()

    def _own(self) -> None:
        if self.owner != os.getpid():  # forked: the parent's child is not this process's to use or kill
            self.server.proc, self.owner = None, os.getpid()

    def start(self) -> None:
        with self.lock:
            self._own()
            self.server.start()

    def read(self, path: str, timeout: float, max_coordinate: float) -> tuple[bytes, list]:
        with self.lock:
            self._own()
            try:
                return self.server.call(read_and_check, (path, max_coordinate), timeout, f"reading {path}")
            except ChildFailure as exc:
                if exc.cause == "start":
                    raise DamagedFileError("STEP reader: the reader process did not start") from None
                if exc.cause == "deadline":
                    raise DamagedFileError(
                        f"path: reading {path} did not finish within {timeout:g} s; the reader was stopped "
                        "(a damaged file can make OCCT loop; raise timeout= for a huge file)") from None
                code = exc.returncode
                how = f"signal {signal.Signals(-code).name}" if code and code < 0 else f"exit code {code}"
                raise DamagedFileError(f"path: OCCT crashed reading {path} ({how}); the file is damaged") from None
            except SurfmodError as exc:
                msg = str(exc)  # every refusal names the file (a kernel failure names its operation)
                raise DamagedFileError(msg if path in msg else f"path: {path}: {msg}") from None
            except Exception as exc:  # noqa: BLE001 - any reader fault is the file's, named
                raise DamagedFileError(f"path: reading {path} failed ({type(exc).__name__}: {exc})") from None

    def close(self) -> None:
        with self.lock:
            if self.owner == os.getpid():
                self.server.close()


_READER = _Reader()
atexit.register(_READER.close)


#: default time limit of one read: a base plus an allowance per megabyte of file
TIMEOUT_BASE = 30.0
TIMEOUT_PER_MB = 10.0
#: default largest coordinate magnitude accepted from a file (model units)
MAX_COORDINATE = 1e9


def read_step_file(path, name: str = "path", *, timeout: float | None = None, max_coordinate: float = MAX_COORDINATE):
    """The TopoDS shape in the STEP file ``path``, read in the worker process.

    ``timeout`` defaults to ``TIMEOUT_BASE + TIMEOUT_PER_MB`` per megabyte of file.
    Raises :class:`~surfmod.errors.SurfmodError` naming ``name`` for a path that is not a
    readable file, and :class:`~surfmod.errors.DamagedFileError` (a ``KernelError``) naming
    the file when its text holds NaN or infinity (:func:`surfmod.checks.step_file`), or OCCT
    refuses it, crashes on it, runs past ``timeout`` seconds, or yields NaN or coordinates
    beyond ``max_coordinate``.

    >>> import os, tempfile, surfmod as sm
    >>> path = os.path.join(tempfile.mkdtemp(), "p.step")
    >>> sm.export_step(sm.sphere(1.0), path)
    >>> read_step_file(path).ShapeType().name
    'TopAbs_SHELL'
    """
    if timeout is not None:
        timeout = checks.positive(timeout, "timeout")
    max_coordinate = checks.positive(max_coordinate, "max_coordinate")
    p = checks.step_file(path, name)
    if timeout is None:
        timeout = TIMEOUT_BASE + TIMEOUT_PER_MB * p.stat().st_size / 1e6
    _READER.start()  # the child imports OCCT while this process does the same
    from .occ.step import brep_from_bytes

    try:
        data, (turned, at_odds) = _READER.read(str(p), timeout, max_coordinate)
    except DamagedFileError as exc:
        msg = str(exc)
        raise DamagedFileError(msg if msg.startswith(f"{name}:") else f"{name}: {msg.removeprefix('path: ')}") from None
    shape = brep_from_bytes(data)
    for number, volume in turned:
        warnings.warn(f"{p.name}: solid {number} is inside out in the file (enclosed volume {volume:.6g}): "
                      "read outward", InsideOutWarning, stacklevel=3)
    for number, edges, faces in at_odds:
        warnings.warn(f"{p.name}: solid {number} is inconsistently oriented: {edges} edge(s) run the same way in "
                      f"both their faces (faces {', '.join(map(str, faces[:10]))}{' ...' if len(faces) > 10 else ''})",
                      InsideOutWarning, stacklevel=3)
    return shape


def stop_worker() -> None:
    """Stop the reader process (it restarts on the next read); also done at exit.

    >>> stop_worker()
    """
    _READER.close()
