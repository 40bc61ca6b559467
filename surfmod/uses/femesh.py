"""Finite element meshes of parts with a target element size (gmsh), written via meshio.

The same concept as :mod:`surfmod.cli.femesh` (the ``surfmod femesh`` command over this).
"""

from __future__ import annotations

import tempfile
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .. import checks, child
from ..atomic import atomic_path, target_path
from ..errors import KernelError, SurfmodError
from ..extras import require
from ..meshing.brep import tessellate_shape
from ..inputs import to_shape


FORMATS = {".msh": "gmsh", ".vtu": "vtu", ".inp": "abaqus"}
_CELLS = {("surface", 1): "triangle", ("surface", 2): "triangle6",
          ("volume", 1): "tetra", ("volume", 2): "tetra10"}


@dataclass(frozen=True)
class FEMesh:
    """A finite element mesh: ``mesh`` is a ``meshio.Mesh`` holding only the elements
    of ``kind`` (``"surface"``: triangles, ``"volume"``: tetrahedra; 6/10-node when
    ``order=2``) and ``quality`` the element-quality figures that mean something for
    that element type, each as ``{"min", "mean", "max"}``:

    * ``gamma`` (gmsh): inscribed/circumscribed radius ratio, 1 for the regular element;
    * ``SICN`` (gmsh): signed inverse condition number, <= 0 for an inverted element;
    * ``min_angle`` (degrees): the smallest dihedral angle of each tetrahedron (the
      smallest corner angle of each triangle); slivers show here when gamma hides them;
    * ``SJ`` (gmsh's scaled Jacobian) for ``order=2`` only: a straight-sided element's
      Jacobian is constant, so for linear elements it is 1 and says nothing;

    plus, for tetrahedra gmsh made from the B-rep, ``quality["chordal"]``: how far the
    straight boundary triangles are from the exact faces (``max_deviation``, from their
    edge midpoints) and
    the resulting bound on the tetrahedra's volume error (``volume_bound``, see
    :func:`_chordal_error`); ``quality["surface"]`` instead when the tetrahedra were made
    from surfmod's measured triangulation because gmsh could not mesh the B-rep (see
    :func:`fe_mesh`), and
    ``quality["inverted"]``, the number of elements whose signed volume (tets) is
    not positive (always 0: fe_mesh refuses otherwise), and ``quality["measure"]``, the
    total volume (area for surface meshes) of the elements as gmsh integrates them,
    curved sides included.

    >>> import surfmod as sm, build123d as bd
    >>> fe = sm.fe_mesh(bd.Box(2, 2, 2), size=1.0)
    >>> round(fe.quality["measure"], 9), fe.kind, fe.quality["inverted"]
    (8.0, 'volume', 0)
    """

    mesh: object = field(repr=False)
    kind: str
    order: int
    size: float
    quality: dict

    @property
    def cell_type(self) -> str:
        return _CELLS[(self.kind, self.order)]

    @property
    def points(self) -> np.ndarray:
        return self.mesh.points

    @property
    def cells(self) -> np.ndarray:
        return self.mesh.get_cells_type(self.cell_type)

    @property
    def n_elements(self) -> int:
        return len(self.cells)

    @property
    def volume(self) -> float:
        """Sum of the (straight-sided) tetrahedron volumes."""
        if self.kind != "volume":
            raise SurfmodError("kind: a surface mesh has no volume")
        t = self.points[self.cells[:, :4]]
        return float(np.abs(np.einsum("ij,ij->i", t[:, 1] - t[:, 0], np.cross(t[:, 2] - t[:, 0], t[:, 3] - t[:, 0]))).sum() / 6)

    @property
    def area(self) -> float:
        """Sum of the (straight-sided) triangle areas of a surface mesh."""
        if self.kind != "surface":
            raise SurfmodError("kind: area is measured on surface meshes")
        t = self.points[self.cells[:, :3]]
        return float(np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum() / 2)

    def export(self, path) -> None:
        """Deprecated (one release): :func:`surfmod.export_fe_mesh`, the one name, beside
        ``export_step``/``export_stl``."""
        warnings.warn("FEMesh.export is deprecated: use sm.export_fe_mesh(mesh, path)", DeprecationWarning, stacklevel=2)
        export_fe_mesh(self, path)

    def __str__(self) -> str:
        q = self.quality
        names = ("gamma", "SICN", "min_angle") + (("SJ",) if "SJ" in q else ())
        angle = "min dihedral angle" if self.kind == "volume" else "min angle"
        labels = {"gamma": "gamma (inradius ratio)", "SICN": "SICN", "min_angle": f"{angle} (deg)",
                  "SJ": "scaled Jacobian"}
        lines = [f"FE mesh: {self.n_elements} {self.cell_type} elements, {len(self.points)} nodes, target size "
                 f"{self.size:g}, inverted elements {q['inverted']}"]
        if "chordal" in q:
            ch = q["chordal"]
            lines.append(f"  boundary chord error (edge midpoints to the exact faces, x4/3) max {ch['max_deviation']:.3g}; tet volume "
                         f"{self.volume:.6g} vs the solid's within {ch['volume_bound']:.3g}")
        if "surface" in q:
            sf = q["surface"]
            split = f" of its {sf['regions']} material regions" if sf.get("split") else ""
            lines.append(f"  meshed from the measured surface triangulation{split} at tolerance {sf['tolerance']:.3g} "
                         f"(gmsh could not mesh the B-rep; max deviation {sf['max_deviation']:.3g}, tet volume "
                         f"{self.volume:.6g} vs BRepGProp {sf['reference_volume']:.6g}, bound {sf['volume_bound']:.3g})")
        for name in names:
            # 3 significant digits: a sliver's 2e-5 must not print as 0.000
            lines.append(f"  {labels[name]:<28s} min {q[name]['min']:.3g} mean {q[name]['mean']:.3g}")
        return "\n".join(lines)


def _stats(values: np.ndarray) -> dict:
    return {"min": float(values.min()), "mean": float(values.mean()), "max": float(values.max())}


def signed_volumes(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Signed volume of each tetrahedron (corner nodes ``tets[:, :4]``, gmsh's order:
    positive for a valid element).

    >>> signed_volumes(np.eye(4, 3, -1), np.array([[0, 1, 2, 3], [0, 2, 1, 3]])).tolist()
    [0.16666666666666666, -0.16666666666666666]
    """
    t = points[tets[:, :4]]
    return np.einsum("ij,ij->i", t[:, 1] - t[:, 0], np.cross(t[:, 2] - t[:, 0], t[:, 3] - t[:, 0])) / 6


def min_dihedral_angles(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Smallest of the six dihedral angles of each tetrahedron, in degrees (70.53 for the
    regular tetrahedron, near 0 for a sliver).

    >>> regular = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    >>> round(float(min_dihedral_angles(regular, np.array([[0, 1, 2, 3]]))[0]), 4)
    70.5288
    """
    t = points[tets[:, :4]]
    faces = ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))  # face k is opposite node k
    normals = []
    for k, (a, b, c) in enumerate(faces):
        n = np.cross(t[:, b] - t[:, a], t[:, c] - t[:, a])
        # orient outwards: away from the opposite node
        n *= -np.sign(np.einsum("ij,ij->i", n, t[:, k] - t[:, a]))[:, None]
        normals.append(n / np.linalg.norm(n, axis=1, keepdims=True))
    worst = np.full(len(t), np.pi)
    for i in range(4):
        for j in range(i + 1, 4):
            cos = np.clip(-np.einsum("ij,ij->i", normals[i], normals[j]), -1.0, 1.0)
            worst = np.minimum(worst, np.arccos(cos))
    return np.degrees(worst)


def min_triangle_angles(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Smallest corner angle of each triangle, in degrees.

    >>> round(float(min_triangle_angles(np.eye(3), np.array([[0, 1, 2]]))[0]), 6)
    60.0
    """
    t = points[tris[:, :3]]
    worst = np.full(len(t), 180.0)
    for k in range(3):
        a, b = t[:, (k + 1) % 3] - t[:, k], t[:, (k + 2) % 3] - t[:, k]
        cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        worst = np.minimum(worst, np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return worst


#: gmsh's OCC healing, tried when a part does not mesh as read (real STEP parts: tiny or
#: degenerate edges, faces that touch without sharing edges make "overlapping facets")
HEALING = {
    "Geometry.OCCFixDegenerated": 1,
    "Geometry.OCCFixSmallEdges": 1,
    "Geometry.OCCFixSmallFaces": 1,
    "Geometry.OCCSewFaces": 1,
    "Geometry.OCCMakeSolids": 1,
}


@contextmanager
def _gmsh_model(name: str):
    """gmsh, initialized (if no caller did) and holding one fresh model ``name`` (gmsh is
    one global state, and each run has a child process of its own, :func:`_gmsh_in_child`).
    gmsh's own exceptions become ``_GmshFailure`` (retried healed, then reported); the
    model is removed afterwards."""
    gmsh = require("gmsh", "fem", "sm.fe_mesh")  # the optional extra 'fem', loaded on the first FE mesh only
    own = not gmsh.isInitialized()
    if own:
        gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add(name)
        yield gmsh
    except SurfmodError:
        raise
    except Exception as exc:
        raise _GmshFailure(str(exc)) from exc
    finally:
        try:
            gmsh.model.remove()
        except Exception:  # pragma: no cover
            pass
        if own:
            gmsh.finalize()


def _run_gmsh(brep: Path, msh: Path, dim: int, size: float, order: int, heal: bool) -> dict:
    """Mesh the BREP file with gmsh, write ``msh``; return gmsh's qualities per element.

    Each solid is its own gmsh volume; solids of an assembly that touch or overlap are
    meshed independently (no conformal interface), as a part list is."""
    with _gmsh_model("surfmod") as gmsh:
        for name, value in HEALING.items():
            gmsh.option.setNumber(name, value if heal else 0)
        gmsh.model.occ.importShapes(str(brep))
        gmsh.model.occ.synchronize()
        if dim == 3 and not gmsh.model.getEntities(3):
            if heal:  # the part had solids when it failed as read
                raise _GmshFailure("gmsh's healing left no volume")
            raise SurfmodError("kind: a volume mesh needs a closed solid; obj has no solid")
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
        quality = _generate(gmsh, msh, dim, size, order)
        if dim == 3:
            quality["chordal"] = _chordal_error(gmsh)
        return quality


#: A triangle's chord error is sampled at its edge midpoints: for a sag that is quadratic
#: over the triangle (any smooth surface, to leading order) and zero at the corners,
#: ``sum c_ij b_i b_j``, the midpoints give ``c_ij / 4`` and the largest value over the
#: triangle is at most ``max|c_ij| / 3``, 4/3 of the largest midpoint sample.
_SAMPLE_FACTOR = 4.0 / 3.0


def _chordal_error(gmsh) -> dict:
    """How far gmsh's straight boundary triangles (corner nodes) are from the exact
    faces they mesh: the distance of each edge midpoint to its face's surface (gmsh's
    ``getClosestPoint``, once per edge of each face), times 4/3 for the triangle (see
    :data:`_SAMPLE_FACTOR`).  Returns ``{"max_deviation", "volume_bound"}``, the bound
    being sum(area x deviation): the straight-sided tetrahedra's volume is the solid's
    within it."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    tags = np.asarray(tags, dtype=np.int64)
    position = np.zeros((int(tags.max(initial=0)) + 1, 3))
    position[tags] = np.asarray(coords).reshape(-1, 3)
    deviation, bound = 0.0, 0.0
    for _, tag in gmsh.model.getEntities(2):
        types, _, nodes = gmsh.model.mesh.getElements(2, tag)
        for etype, enodes in zip(types, nodes):
            n_nodes = gmsh.model.mesh.getElementProperties(etype)[3]
            corners = np.asarray(enodes, dtype=np.int64).reshape(-1, n_nodes)[:, :3]
            if not len(corners):
                continue
            edges = np.sort(np.stack([corners, np.roll(corners, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
            unique, which = np.unique(edges, axis=0, return_inverse=True)
            middle = position[unique].mean(axis=1)
            closest, _ = gmsh.model.getClosestPoint(2, tag, middle.ravel())
            sag = np.linalg.norm(np.asarray(closest).reshape(-1, 3) - middle, axis=1)
            per_triangle = _SAMPLE_FACTOR * sag[which.reshape(-1)].reshape(-1, 3).max(axis=1)
            t = position[corners]
            area = np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1) / 2
            deviation = max(deviation, float(per_triangle.max()))
            bound += float(area @ per_triangle)
    return {"max_deviation": deviation, "volume_bound": bound}


def _generate(gmsh, msh: Path, dim: int, size: float, order: int) -> dict:
    """Generate the ``dim`` mesh of gmsh's current model, write ``msh``, return gmsh's
    qualities per element."""
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size / 10)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.model.mesh.generate(dim)
    if order > 1:
        gmsh.model.mesh.setOrder(order)
    _types, tags, _ = gmsh.model.mesh.getElements(dim)
    all_tags = np.concatenate([np.asarray(t) for t in tags]) if len(tags) else np.array([])
    if all_tags.size == 0:
        raise SurfmodError("size: gmsh produced no elements (is the part degenerate?)")
    quality = {}
    names = {"gamma": "gamma", "SICN": "minSICN"} | ({"SJ": "minSJ"} if order > 1 else {})
    for name, gmsh_name in names.items():
        quality[name] = _stats(np.asarray(gmsh.model.mesh.getElementQualities(all_tags, gmsh_name)))
    # gmsh's own element measures (curved elements for order 2)
    quality["measure"] = float(np.sum(gmsh.model.mesh.getElementQualities(all_tags, "volume")))
    gmsh.write(str(msh))
    return quality


def shells_of_triangulation(vertices: np.ndarray, triangles: np.ndarray) -> list:
    """The closed shells of a solid's triangulation: its vertex-connected components, each
    as ``(triangles (T, 3), signed volume)``, the outer shells (positive volume, the
    triangles facing outwards) before the voids (negative), larger first.

    >>> import trimesh
    >>> outer, inner = trimesh.creation.box((4, 4, 4)), trimesh.creation.box((2, 2, 2))
    >>> v = np.vstack([outer.vertices, inner.vertices])
    >>> t = np.vstack([outer.faces, inner.faces[:, ::-1] + len(outer.vertices)])  # a void
    >>> [(len(tris), round(vol, 9)) for tris, vol in shells_of_triangulation(v, t)]
    [(12, 64.0), (12, -8.0)]
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    triangles = np.asarray(triangles)
    n = len(vertices)
    # vertices joined along each triangle's edges: one component per shell
    rows, cols = triangles.ravel(), np.roll(triangles, 1, axis=1).ravel()
    _, label = connected_components(coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)), directed=False)
    shells = []
    for comp in np.unique(label[triangles[:, 0]]):
        tris = triangles[label[triangles[:, 0]] == comp]
        t = np.asarray(vertices, float)[tris]
        volume = float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6)
        shells.append((tris, volume))
    return sorted(shells, key=lambda shell: -shell[1])


def _run_gmsh_triangulation(surfaces, msh: Path, size: float, order: int) -> dict:
    """Tetrahedra inside closed triangulations: ``surfaces`` is a list of ``(vertices
    (V, 3), triangles (T, 3))``, one closed triangulation per solid.  Each of its shells
    becomes a gmsh discrete surface whose triangles are kept as the boundary mesh; each
    outer shell bounds a volume of its own, with the void shells inside it as holes (a
    void is not filled); the interior is meshed at ``size``."""
    with _gmsh_model("surfmod-triangulation") as gmsh:
        first = 1
        for vertices, triangles in surfaces:
            vertices = np.asarray(vertices, float)
            volumes = []  # (outer surface, its box, its void surfaces)
            for tris, volume in shells_of_triangulation(vertices, triangles):
                surface = gmsh.model.addDiscreteEntity(2)
                used = np.unique(tris)
                gmsh.model.mesh.addNodes(2, surface, used + first, vertices[used].ravel())
                gmsh.model.mesh.addElementsByType(surface, 2, [], (tris + first).ravel())
                box = (vertices[used].min(axis=0), vertices[used].max(axis=0))
                if volume > 0 or not volumes:
                    volumes.append((surface, box, []))
                    continue
                # a void goes into the smallest outer shell whose box holds its box
                holders = [v for v in volumes if np.all(v[1][0] <= box[0]) and np.all(box[1] <= v[1][1])]
                min(holders or volumes, key=lambda v: float(np.prod(v[1][1] - v[1][0])))[2].append(surface)
            first += len(vertices)
            for surface, _box, voids in volumes:
                loops = [gmsh.model.geo.addSurfaceLoop([s]) for s in [surface, *voids]]
                gmsh.model.geo.addVolume(loops)
        gmsh.model.geo.synchronize()
        return _generate(gmsh, msh, 3, size, order)


class _GmshFailure(Exception):
    """gmsh could not mesh the part as given (retried healed, then reported)."""


def fe_mesh(obj, size: float, order: int = 1, kind: str = "volume", *, path=None,
            max_elements: int = 2_000_000, progress: bool = False) -> FEMesh:
    """Triangle (``kind="surface"``) or tetrahedral (``kind="volume"``) FE mesh of a part
    with target element ``size`` (gmsh, also refined by curvature), ``order`` 1 or 2.

    ``obj``: a build123d shape, surfmod surface(s) or a STEP path.  The part goes to
    gmsh as a BREP file (exact geometry); the mesh comes back through meshio.  A part
    gmsh cannot mesh as read is retried with gmsh's OCC healing (:data:`HEALING`).  A
    volume it still cannot mesh is meshed from surfmod's watertight triangulation of
    each solid, measured against the exact faces at ``min(1e-3 x diagonal, size / 4)``
    (``surfmod mesh``'s STL): its triangles are kept as the boundary and gmsh fills the
    inside (void shells stay empty); the tetrahedra's volume must equal BRepGProp's within
    area x measured deviation, and the result says so (``quality["surface"]``, printed).
    Where that triangulation crosses itself (a solid whose shells touch along a curve
    without sharing an edge there, as a void whose rim lies on the outer shell), each
    solid is split into its material regions (:func:`surfmod.occ.booleans.material_regions`,
    OCCT's ``BOPAlgo_MakerVolume``), whose boundaries share their contact edges, and those
    are triangulated and filled (``quality["surface"]["split"]``).  Where gmsh's boundary
    recovery fails on a triangulation, it is retried once at half the tolerance
    (:data:`RECOVERY_RETRY_SHARE`; ``quality["surface"]["tolerance"]`` is the one used).  A part none of
    these can mesh raises ``SurfmodError`` naming the file and gmsh's reasons.
    Every tetrahedron's signed volume is checked: an inverted element is an error, never
    a result.  With ``path`` the mesh is also written (``.msh``, ``.vtu``, ``.inp``).  Meshes estimated
    (from the bounding box and ``size``) above ``max_elements`` elements are refused
    before gmsh runs; raise ``max_elements`` to allow them.  ``progress`` shows a tqdm bar
    over the attempts (:data:`ATTEMPTS`) and the element checks.

    >>> import surfmod as sm, build123d as bd
    >>> m = sm.fe_mesh(bd.Box(2, 2, 2), size=1.0)
    >>> round(m.volume, 9), m.cell_type, m.quality["gamma"]["min"] > 0.2
    (8.0, 'tetra', True)
    """
    meshio = require("meshio", "fem", "sm.fe_mesh")

    from ..occ.properties import bounding_box
    from ..occ.step import write_brep
    from ..occ.topo import solids_of

    size = checks.positive(size, "size")
    if order not in (1, 2):
        raise SurfmodError(f"order: expected 1 or 2, got {order!r}")
    if kind not in ("surface", "volume"):
        raise SurfmodError(f"kind: expected 'surface' or 'volume', got {kind!r}")
    shape = to_shape(obj, "obj")
    if kind == "volume":
        if not solids_of(shape):
            shape = to_shape(obj, "obj", solid=True)
    box = bounding_box(shape)
    extent = float(np.max(box[1] - box[0]))
    if size > 10 * extent:
        raise SurfmodError(f"size: {size:g} is far larger than the part (extent {extent:.4g})")
    dims = np.maximum(box[1] - box[0], size)
    if kind == "volume":  # about 6 tetrahedra per cube of the element size
        estimate = 6.0 * float(np.prod(dims / size))
    else:  # 2 triangles per square on the box's faces
        estimate = 4.0 * float(dims[0] * dims[1] + dims[1] * dims[2] + dims[0] * dims[2]) / size**2
    checks.work(estimate, max_elements, "max_elements", f"a {kind} mesh with element size {size:g} of a part of extent {extent:.4g}")
    cell = _CELLS[(kind, order)]
    failures = []
    # each gmsh run has a time budget from the same estimate: gmsh makes well over
    # GMSH_ELEMENTS_PER_SECOND elements a second on a busy machine, so a run past it is
    # stuck.  One budget per run, not one for all attempts: surfmod's own triangulation
    # of the later attempts, and a loaded machine, must not leave gmsh a second to mesh
    # in; the whole wait is bounded by len(attempts) + 2 budgets (each triangulation
    # attempt retries a failed boundary recovery once, RECOVERY_RETRY_SHARE)
    seconds = GMSH_SECONDS + estimate / GMSH_ELEMENTS_PER_SECOND

    with tempfile.TemporaryDirectory(prefix="surfmod-gmsh-") as tmp, \
            tqdm(total=2, desc="fe_mesh", unit="step", disable=not progress, leave=False) as bar:
        brep, msh = Path(tmp) / "part.brep", Path(tmp) / "part.msh"
        write_brep(shape, brep)
        # as read, healed by gmsh, then (volumes) from surfmod's measured closed
        # triangulation, of each solid and then of each solid's material regions
        attempts = ATTEMPTS[kind]
        for attempt in attempts:
            bar.set_postfix_str(attempt)
            try:
                if attempt in ("triangulation", "regions"):
                    quality, surface = _triangulation_attempt(shape, msh, size, order, seconds,
                                                              regions=attempt == "regions")
                else:
                    args = (brep, msh, 3 if kind == "volume" else 2, size, order, attempt == "healed")
                    quality = _gmsh_in_child(_run_gmsh, args, seconds)
            except _GmshFailure as exc:
                failures.append(f"{attempt}: {exc}")
                continue
            bar.update()
            full = meshio.read(msh, file_format="gmsh")
            points, data = _cells_of(full, cell)
            inverted = int(np.sum(signed_volumes(points, data) <= 0)) if kind == "volume" else 0
            if inverted:
                failures.append(f"{attempt}: {inverted} inverted tetrahedra")
                continue
            if attempt in ("triangulation", "regions"):
                miss = abs(float(signed_volumes(points, data).sum()) - surface["reference_volume"])
                if miss > surface["volume_bound"]:
                    failures.append(f"{attempt}: the tetrahedra hold {miss:.3g} more or less than "
                                    f"BRepGProp's volume, beyond the triangulation's bound {surface['volume_bound']:.3g}")
                    continue
                quality["surface"] = surface | {"split": attempt == "regions"}
            bar.update()
            break
        else:
            tried = ", ".join(attempts[:-1]) + " or " + attempts[-1]
            raise SurfmodError(
                f"obj: {Path(obj).name if isinstance(obj, (str, Path)) else 'this part'}: gmsh cannot {kind}-mesh "
                f"it at size {size:g}, tried {tried} "
                f"({'; '.join(dict.fromkeys(failures))})"
            )
    quality["inverted"] = 0
    angles = min_dihedral_angles(points, data) if kind == "volume" else min_triangle_angles(points, data)
    quality["min_angle"] = _stats(angles)
    result = FEMesh(meshio.Mesh(points, [(cell, data)]), kind, order, size, quality)
    if path is not None:
        export_fe_mesh(result, path)
    return result


#: What fe_mesh tries, in order: gmsh on the B-rep as read, then healed by gmsh's OCC
#: healing (:data:`HEALING`); for volumes, gmsh filling surfmod's measured triangulation of
#: each solid, then of each solid's material regions (:func:`surfmod.occ.booleans.material_regions`:
#: a solid whose shells touch along a curve without sharing an edge there has triangles
#: crossing at that curve, which gmsh's boundary recovery rejects).
ATTEMPTS = {"volume": ("as read", "healed", "triangulation", "regions"), "surface": ("as read", "healed")}

#: the time budget of each gmsh run of fe_mesh: this many seconds plus one per this many
#: estimated elements (gmsh makes tens of thousands a second); past it gmsh is stuck
GMSH_SECONDS = 60.0
GMSH_ELEMENTS_PER_SECOND = 1000.0

#: The fallback triangulation's chordal tolerance, as a share of the bounding-box diagonal
#: (the STL standard of ``surfmod mesh``), and at most this share of the element size.
TRIANGULATION_SHARE = 1e-3
TRIANGULATION_SIZE_SHARE = 0.25

#: gmsh's boundary recovery (TetGen's, the 3-D Delaunay's) fails on some closed,
#: manifold, non-crossing triangulations and not on others of the same part at another
#: tolerance: pythonocc_11752.stp's body region (long, thin boundary triangles on its
#: 1147 mm holes of radius 1.08 mm beside elements of 86 mm; min gamma 3e-10 where it
#: meshes) at tolerance 1.30 fails from OCCT 8.0's BRepMesh (52362 triangles) and meshes
#: from OCCT 7.9's (52374: 6 vertices more on a few faces); on 8.0 1.0 fails too, 0.65,
#: 0.80 and 2.0 mesh, and 0.65 meshes on 7.9.  That failure, and only it (a crossing or a missing
#: triangulation is not the luck of the mesh), is retried once at the tolerance times
#: this share: finer, so the documented bound still holds.
RECOVERY_FAILURE = "Could not recover boundary mesh"
RECOVERY_RETRY_SHARE = 0.5


def _gmsh_in_child(fn, args: tuple, seconds: float):
    """``fn(*args)`` (a gmsh run) in a child process that must answer within ``seconds``:
    gmsh can loop for ever on a damaged face, inside one C call."""
    try:
        return child.call(fn, args, seconds, "gmsh")
    except child.ChildFailure as exc:
        raise _GmshFailure(str(exc)) from None


def _triangulation_attempt(shape, msh: Path, size: float, order: int, seconds: float, *, regions: bool = False):
    """Volume-mesh every solid of ``shape`` from its watertight triangulation, measured
    against the exact faces (:func:`surfmod.meshing.brep.tessellate_shape`), for parts
    whose B-rep gmsh cannot mesh; with ``regions`` each solid is first split into its
    material regions (:func:`surfmod.occ.booleans.material_regions`), each triangulated and
    filled on its own (gmsh has ``seconds`` for that); when gmsh's boundary recovery fails,
    once more from a finer triangulation (:data:`RECOVERY_RETRY_SHARE`).  Returns gmsh's
    qualities and what the boundary is:
    ``{"tolerance", "max_deviation", "reference_volume" (BRepGProp of the solids),
    "volume_bound", "regions" (pieces meshed)}``: every boundary point lies within
    ``max_deviation`` of the part, so the tetrahedra's volume is within ``volume_bound`` =
    area x deviation of the part's."""
    from ..occ.properties import bounding_box, gprops
    from ..occ.topo import solids_of
    from ..occ.booleans import material_regions

    box = bounding_box(shape)
    tolerance = min(TRIANGULATION_SHARE * float(np.linalg.norm(box[1] - box[0])), TRIANGULATION_SIZE_SHARE * size)
    solids = solids_of(shape)
    reference = sum(abs(gprops(solid)["volume"]) for solid in solids)
    pieces = solids
    if regions:
        try:
            pieces = [region for solid in solids for region in material_regions(solid)]
        except KernelError as exc:
            raise _GmshFailure(f"no material regions: {exc}") from None
    failed = None  # gmsh's boundary recovery failure at the first tolerance
    for tol in (tolerance, tolerance * RECOVERY_RETRY_SHARE):
        surfaces, deviation, bound = [], 0.0, 0.0
        for piece in pieces:
            try:
                mesh = tessellate_shape(piece, tol)
            except SurfmodError as exc:
                raise _GmshFailure(f"no measured triangulation: {exc}") from None
            surfaces.append((mesh.vertices, mesh.triangles()))
            dev = max(float(mesh.info["max_deviation"]), tol)
            deviation = max(deviation, dev)
            bound += mesh.area * dev
        try:
            quality = _gmsh_in_child(_run_gmsh_triangulation, (surfaces, msh, size, order), seconds)
        except _GmshFailure as exc:
            if failed is not None:
                raise _GmshFailure(f"{failed} at tolerance {tolerance:.3g}, {exc} at {tol:.3g}") from None
            if RECOVERY_FAILURE not in str(exc):
                raise
            failed = exc
            continue
        return quality, {"tolerance": tol, "max_deviation": deviation, "reference_volume": reference,
                         "volume_bound": bound, "regions": len(pieces)}


def _cells_of(full, cell: str):
    """Points and connectivity of the ``cell`` blocks of a meshio mesh, unused nodes
    dropped."""
    blocks = [c.data for c in full.cells if c.type == cell]
    data = np.concatenate(blocks) if blocks else np.zeros((0, 3), dtype=int)
    used = np.unique(data)
    remap = np.full(len(full.points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return full.points[used], remap[data]


def export_fe_mesh(mesh, path) -> None:
    """Write an :class:`FEMesh` (or a ``meshio.Mesh``) as ``.msh`` (gmsh 4.1 ASCII),
    ``.vtu`` (VTK XML) or ``.inp`` (Abaqus), atomically.

    >>> import surfmod as sm, build123d as bd, tempfile, os, meshio
    >>> p = os.path.join(tempfile.mkdtemp(), "box.vtu")
    >>> sm.export_fe_mesh(sm.fe_mesh(bd.Box(1, 1, 1), 0.5, kind="surface"), p)
    >>> meshio.read(p).cells[0].type
    'triangle'
    """
    meshio = require("meshio", "fem", "sm.fe_mesh")

    target = target_path(path, "path", tuple(FORMATS))
    m = mesh.mesh if isinstance(mesh, FEMesh) else mesh
    if not isinstance(m, meshio.Mesh):
        raise SurfmodError(f"mesh: expected an FEMesh or meshio.Mesh, got {type(mesh).__name__}")
    fmt = FORMATS[target.suffix.lower()]
    with atomic_path(target) as tmp:
        if fmt == "gmsh":
            meshio.write(tmp, m, file_format="gmsh", binary=False)
        else:
            meshio.write(tmp, m, file_format=fmt)
