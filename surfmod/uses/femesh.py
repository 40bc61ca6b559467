"""Finite element meshes of parts with a target element size (gmsh), written via meshio."""

from __future__ import annotations

import tempfile
import threading
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import checks
from ..errors import SurfmodError

_GMSH_LOCK = threading.Lock()  # gmsh keeps global state: one mesh at a time

FORMATS = {".msh": "gmsh", ".vtu": "vtu", ".inp": "abaqus"}
_CELLS = {("surface", 1): "triangle", ("surface", 2): "triangle6",
          ("volume", 1): "tetra", ("volume", 2): "tetra10"}


@dataclass(frozen=True)
class FEMesh:
    """A finite element mesh: ``mesh`` is a ``meshio.Mesh`` holding only the elements
    of ``kind`` (``"surface"``: triangles, ``"volume"``: tetrahedra; 6/10-node when
    ``order=2``), ``quality`` gmsh's element-quality statistics (scaled Jacobian
    ``minSJ`` (1 for every straight-sided element, informative for ``order=2``),
    signed inverse condition number ``minSICN`` and inscribed/circumscribed radius
    ratio ``gamma``: min, mean, max each) plus ``quality["measure"]``, the total volume
    (area for surface meshes) of the elements as gmsh integrates them, curved sides
    included.

    >>> import surfmod as sm, build123d as bd
    >>> fe = sm.fe_mesh(bd.Box(2, 2, 2), size=1.0)
    >>> round(fe.quality["measure"], 9), fe.kind
    (8.0, 'volume')
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
        """Same as :func:`export_fe_mesh`."""
        export_fe_mesh(self, path)

    def __str__(self) -> str:
        q = self.quality
        return (
            f"FE mesh: {self.n_elements} {self.cell_type} elements, {len(self.points)} nodes, target size {self.size:g}\n"
            f"  scaled Jacobian min {q['minSJ']['min']:.3f} mean {q['minSJ']['mean']:.3f}\n"
            f"  SICN            min {q['minSICN']['min']:.3f} mean {q['minSICN']['mean']:.3f}\n"
            f"  gamma           min {q['gamma']['min']:.3f} mean {q['gamma']['mean']:.3f}"
        )


def _gmsh():
    try:
        import gmsh
    except ImportError:  # pragma: no cover
        raise SurfmodError("fe_mesh needs gmsh (pip install gmsh)") from None
    return gmsh


def _run_gmsh(brep: Path, msh: Path, dim: int, size: float, order: int) -> dict:
    gmsh = _gmsh()
    with _GMSH_LOCK:
        own = not gmsh.isInitialized()
        if own:
            gmsh.initialize(interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.add("surfmod")
            gmsh.model.occ.importShapes(str(brep))
            gmsh.model.occ.synchronize()
            if dim == 3 and not gmsh.model.getEntities(3):
                raise SurfmodError("kind: a volume mesh needs a closed solid; obj has no solid")
            gmsh.option.setNumber("Mesh.MeshSizeMax", size)
            gmsh.option.setNumber("Mesh.MeshSizeMin", size / 10)
            gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
            gmsh.option.setNumber("Mesh.Binary", 0)
            gmsh.model.mesh.generate(dim)
            if order > 1:
                gmsh.model.mesh.setOrder(order)
            quality = {}
            types, tags, _ = gmsh.model.mesh.getElements(dim)
            all_tags = np.concatenate([np.asarray(t) for t in tags]) if len(tags) else np.array([])
            if all_tags.size == 0:
                raise SurfmodError("size: gmsh produced no elements (is the part degenerate?)")
            for name in ("minSJ", "minSICN", "gamma"):
                q = np.asarray(gmsh.model.mesh.getElementQualities(all_tags, name))
                quality[name] = {"min": float(q.min()), "mean": float(q.mean()), "max": float(q.max())}
            # gmsh's own element measures (curved elements for order 2)
            quality["measure"] = float(np.sum(gmsh.model.mesh.getElementQualities(all_tags, "volume")))
            gmsh.write(str(msh))
            return quality
        except SurfmodError:
            raise
        except Exception as exc:
            raise SurfmodError(f"obj: gmsh failed to mesh the part ({exc})") from exc
        finally:
            try:
                gmsh.model.remove()
            except Exception:  # pragma: no cover
                pass
            if own:
                gmsh.finalize()


def fe_mesh(obj, size: float, order: int = 1, kind: str = "volume", *, path=None,
            max_elements: int = 2_000_000) -> FEMesh:
    """Triangle (``kind="surface"``) or tetrahedral (``kind="volume"``) FE mesh of a part
    with target element ``size`` (gmsh, also refined by curvature), ``order`` 1 or 2.

    ``obj``: a build123d shape, surfmod surface(s) or a STEP path.  The part goes to
    gmsh as a BREP file (exact geometry); the mesh comes back through meshio.  With
    ``path`` the mesh is also written (``.msh``, ``.vtu``, ``.inp``).  Meshes estimated
    (from the bounding box and ``size``) above ``max_elements`` elements are refused
    before gmsh runs; raise ``max_elements`` to allow them.

    >>> import surfmod as sm, build123d as bd
    >>> m = sm.fe_mesh(bd.Box(2, 2, 2), size=1.0)
    >>> round(m.volume, 9), m.cell_type, m.quality["gamma"]["min"] > 0.2
    (8.0, 'tetra', True)
    """
    import meshio

    from ..occ import uses as occ
    from .inputs import to_shape

    size = checks.positive(size, "size")
    if order not in (1, 2):
        raise SurfmodError(f"order: expected 1 or 2, got {order!r}")
    if kind not in ("surface", "volume"):
        raise SurfmodError(f"kind: expected 'surface' or 'volume', got {kind!r}")
    shape = to_shape(obj, "obj")
    if kind == "volume":
        if not occ.solids_of(shape):
            shape = to_shape(obj, "obj", solid=True)
    box = occ.bounding_box(shape)
    extent = float(np.max(box[1] - box[0]))
    if size > 10 * extent:
        raise SurfmodError(f"size: {size:g} is far larger than the part (extent {extent:.4g})")
    dims = np.maximum(box[1] - box[0], size)
    if kind == "volume":  # about 6 tetrahedra per cube of the element size
        estimate = 6.0 * float(np.prod(dims / size))
    else:  # 2 triangles per square on the box's faces
        estimate = 4.0 * float(dims[0] * dims[1] + dims[1] * dims[2] + dims[0] * dims[2]) / size**2
    checks.work(estimate, max_elements, "max_elements", f"a {kind} mesh with element size {size:g} of a part of extent {extent:.4g}")
    with tempfile.TemporaryDirectory(prefix="surfmod-gmsh-") as tmp:
        brep, msh = Path(tmp) / "part.brep", Path(tmp) / "part.msh"
        occ.write_brep(shape, brep)
        quality = _run_gmsh(brep, msh, 3 if kind == "volume" else 2, size, order)
        full = meshio.read(msh, file_format="gmsh")
    cell = _CELLS[(kind, order)]
    blocks = [c.data for c in full.cells if c.type == cell]
    data = np.concatenate(blocks) if blocks else np.zeros((0, 3), dtype=int)
    used = np.unique(data)
    remap = np.full(len(full.points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    mesh = meshio.Mesh(full.points[used], [(cell, remap[data])])
    result = FEMesh(mesh, kind, order, size, quality)
    if path is not None:
        export_fe_mesh(result, path)
    return result


def export_fe_mesh(mesh, path) -> None:
    """Write an :class:`FEMesh` (or a ``meshio.Mesh``) as ``.msh`` (gmsh 4.1 ASCII),
    ``.vtu`` (VTK XML) or ``.inp`` (Abaqus), atomically.

    >>> import surfmod as sm, build123d as bd, tempfile, os, meshio
    >>> p = os.path.join(tempfile.mkdtemp(), "box.vtu")
    >>> sm.export_fe_mesh(sm.fe_mesh(bd.Box(1, 1, 1), 0.5, kind="surface"), p)
    >>> meshio.read(p).cells[0].type
    'triangle'
    """
    import meshio

    from ..atomic import atomic_path, target_path

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
