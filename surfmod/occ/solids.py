"""Closed solids from faces and shells (``BRepBuilderAPI_Sewing``, ``BRepBuilderAPI_MakeSolid``):
what volume work (mass properties, FE meshes, interference) is given to measure, and the
edges their faces share.  Which faces to turn, and when, is decided above the door
(:func:`surfmod.inputs.closed_solid`)."""

from __future__ import annotations

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepCheck import BRepCheck_NoError, BRepCheck_Shell
from OCP.BRepLib import BRepLib
from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopoDS import TopoDS_Shell, TopoDS_Solid

from ..errors import SurfmodError
from .guard import check_done, kernel
from .topo import shells_of, solids_of
from .topo import explore as _explore

SEW_TOLERANCE = 1e-6


def model_tolerance(shape) -> float:
    """The largest edge tolerance of ``shape`` (what the writing system vouched for)."""
    with kernel("ShapeAnalysis_ShapeTolerance"):
        return float(ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1, TopAbs_EDGE))


def sew_solid(face_shapes, tolerance: float = SEW_TOLERANCE):
    """Sew faces into a closed shell and make an outward-oriented solid.

    Raises ``SurfmodError`` when the faces do not close up.
    """
    with kernel("BRepBuilderAPI_Sewing"):
        sewing = BRepBuilderAPI_Sewing(tolerance)
        for f in face_shapes:
            sewing.Add(f)
        sewing.Perform()
        sewed = sewing.SewedShape()
    shells = shells_of(sewed)
    if len(shells) != 1 or not BRep_Tool.IsClosed_s(shells[0]):
        raise SurfmodError(
            f"obj: the {len(face_shapes)} faces do not sew into one closed shell at tolerance {tolerance:.3g} "
            f"(got {len(shells)} shell(s), free edges remain): volume needs a closed boundary"
        )
    with kernel("BRepBuilderAPI_MakeSolid"):
        maker = BRepBuilderAPI_MakeSolid(shells[0])
        check_done(maker, "BRepBuilderAPI_MakeSolid")
        solid = maker.Solid()
        BRepLib.OrientClosedSolid_s(solid)
    return solid


def solid_of_shell(shell, what: str):
    """A solid bounded by one shell; an open shell is sewn at the model's own tolerance
    first (loose faces that OCCT sewing joins), and refused only if it stays open."""
    if not BRep_Tool.IsClosed_s(shell):
        tol = max(SEW_TOLERANCE, model_tolerance(shell))
        try:
            return sew_solid(_explore(shell, TopAbs_FACE), tol)
        except SurfmodError:
            raise SurfmodError(f"obj: {what} is not closed (free edges remain after sewing at the model's tolerance "
                               f"{tol:.3g}): volume needs a closed boundary") from None
    with kernel("BRepBuilderAPI_MakeSolid"):
        solid = BRepBuilderAPI_MakeSolid(shell).Solid()
        BRepLib.OrientClosedSolid_s(solid)
    return solid


def _faces_outside(shape, owners) -> list[int]:
    inside = {f.__hash__() for owner in owners for f in _explore(owner, TopAbs_FACE)}
    return [k for k, f in enumerate(_explore(shape, TopAbs_FACE)) if f.__hash__() not in inside]


def _edge_uses(solid) -> tuple[list, dict]:
    """The faces of ``solid`` (distinct, explorer order) and, per edge, the
    ``(face position, orientation as the face runs it)`` of its uses."""
    faces, position, uses = [], {}, {}
    for face in _explore(solid, TopAbs_FACE):
        k = position.setdefault(face.__hash__(), len(faces))
        if k == len(faces):
            faces.append(face)
        for edge in _explore(face, TopAbs_EDGE):  # orientation composed with the face's
            uses.setdefault(edge.__hash__(), []).append((k, edge.Orientation()))
    return faces, uses


def _shells_agree(solid) -> bool:
    """True when OCCT finds every edge shared by two faces of each shell of ``solid``
    run one way in one face and the other way in the other (``BRepCheck_Shell``'s
    orientation check): then no face is at odds and :func:`_edge_uses` need not run.
    OCCT's check walks the edges in C++, 5-8 times faster than that Python walk (7.7 ms
    against 37 ms on the 1018 faces of pythonocc_11752); any other answer (a face at odds,
    an open or non-manifold shell) leaves the judgement to the walk."""
    with kernel("BRepCheck_Shell"):
        return all(BRepCheck_Shell(shell).Orientation(True) == BRepCheck_NoError for shell in shells_of(solid))


def face_links(solid) -> tuple[list, set, list]:
    """``(faces, links, odd uses)`` of ``solid``: its faces (distinct, explorer order),
    ``(a, b, odd)`` for faces ``a`` and ``b`` sharing an edge (``odd`` where the edge runs
    the same way in both), and the uses of each edge that runs so; the one pass over the
    edges that :func:`surfmod.inputs.oriented_solid` and :func:`faces_at_odds` share.
    ``([], set(), [])`` when OCCT finds the shells consistent (:func:`_shells_agree`):
    nothing to turn."""
    if _shells_agree(solid):
        return [], set(), []
    with kernel("TopExp_Explorer"):
        faces, uses = _edge_uses(solid)
    shared = [u for u in uses.values() if len(u) == 2 and u[0][0] != u[1][0]]  # seams are not judged
    links = {(u[0][0], u[1][0], u[0][1] == u[1][1]) for u in shared}
    return faces, links, [u for u in shared if u[0][1] == u[1][1]]


def solid_of_faces(faces):
    """A solid of one closed shell of ``faces`` as given (``TopoDS_Face`` s, each
    oriented as it is to face)."""
    with kernel("BRep_Builder"):
        builder, shell, out = BRep_Builder(), TopoDS_Shell(), TopoDS_Solid()
        builder.MakeShell(shell)
        for face in faces:
            builder.Add(shell, face)
        shell.Closed(True)
        builder.MakeSolid(out)
        builder.Add(out, shell)
    return out


def is_closed(shape) -> bool:
    """Whether a shell (or solid) has no free edge (``BRep_Tool.IsClosed``)."""
    return BRep_Tool.IsClosed_s(shape)


def faces_at_odds(shape) -> list[tuple[int, int, list[int]]]:
    """The solids of ``shape`` whose faces disagree, from the model's topology:
    ``(solid number from 1, edges, faces)`` for each solid in which some edge shared by
    two faces runs the same way in both (in a consistently oriented shell each edge runs
    one way in one face and the other way in the other), with the faces (``faces_of``
    order) along such edges.  Seams (an edge used twice by one face) are not judged.

    >>> import build123d as bd
    >>> faces_at_odds(bd.Solid.make_box(1, 2, 3).wrapped)
    []
    """
    out, index = [], None
    with kernel("TopExp_Explorer"):
        for number, solid in enumerate(solids_of(shape), 1):
            faces, _, odd = face_links(solid)
            if odd:
                if index is None:  # the positions in the whole shape, needed only to name faces
                    index = {f.__hash__(): k for k, f in reversed(list(enumerate(_explore(shape, TopAbs_FACE))))}
                out.append((number, len(odd), sorted({index.get(faces[k].__hash__(), -1) for u in odd for k, _ in u})))
    return out


def left_out_faces(shape) -> list[int]:
    """Indices (``faces_of`` order) of the faces :func:`surfmod.inputs.closed_solid`
    leaves out: those outside every solid when the shape has solids (open shells and
    loose faces beside them: they enclose no volume), outside every shell when it has
    shells but no solid.

    >>> import build123d as bd
    >>> left_out_faces(bd.Compound([bd.Box(1, 1, 1), bd.Face.make_rect(1, 1)]).wrapped)
    [6]
    """
    owners = solids_of(shape) or shells_of(shape)
    return _faces_outside(shape, owners) if owners else []


def open_faces(shape) -> list[int]:
    """Indices (``faces_of`` order) of the faces in no closed shell: open shells and loose
    faces, whose free edges a mesh of the shape cannot close.

    >>> import build123d as bd
    >>> open_faces(bd.Compound([bd.Box(1, 1, 1), bd.Face.make_rect(1, 1)]).wrapped)
    [6]
    """
    return _faces_outside(shape, [s for s in shells_of(shape) if BRep_Tool.IsClosed_s(s)])


def loose_faces_solid(shape):
    """A solid of the faces of ``shape`` (which has no shell): one closed shell when they
    share their edges already (e.g. one periodic face, a full sphere or torus closed by
    its own seam and poles), else sewn at the model's tolerance."""
    faces = _explore(shape, TopAbs_FACE)
    if not faces:
        raise SurfmodError("obj: has no faces, so no solid to measure")
    builder = BRep_Builder()
    shell = TopoDS_Shell()
    builder.MakeShell(shell)
    for f in faces:
        builder.Add(shell, f)
    if BRep_Tool.IsClosed_s(shell):
        return solid_of_shell(shell, "the shell of its faces")
    return sew_solid(faces, max(SEW_TOLERANCE, model_tolerance(shape)))
