"""Tessellation to a chordal tolerance, with the deviation *measured*, not estimated: surfmod
surfaces on the NumPy evaluator (:mod:`surfmod.meshing.gridmesh`, :mod:`surfmod.meshing.adaptive`),
build123d shapes through BRepMesh measured face by face (:mod:`surfmod.meshing.brep`).
See :doc:`/guide/meshing` (section "Tessellation of a surface").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..surface import Surface, model_size
from .brep import MAX_TRIANGLES, tessellate_shape
from .adaptive import Refiner
from .deviation import DENSE
from .domain import domain_sides, shared_points
from .gridmesh import grid_tessellate
from .polymesh import Mesh
from tqdm import tqdm

#: Tolerances below this fraction of the object size cannot be certified in float64.
MIN_RELATIVE_TOLERANCE = 1e-10


#: the fewest triangles a mesh within the tolerance took per triangle of the curvature
#: estimate, measured on planes' neighbours to superellipsoids (cylinders 1.5: one
#: curved direction; spheres, tori, B-splines 2-3, where a cell's diagonal sags more than
#: its sides; creased superellipsoids 6-60): the estimate times this is a floor of the
#: work, so a tolerance refused by it is refused before any meshing
MESH_OVERHEAD = 1.4


def estimate_triangles(s, tolerance: float, size: float) -> float:
    """Order-of-magnitude triangle count for ``tolerance`` from sampled principal curvatures:
    a chord of length ``h`` on curvature ``k`` deviates ``k h^2 / 8``."""
    (u0, u1), (v0, v1) = s.domain
    n = 24
    us = u0 + (np.arange(n) + 0.5) / n * (u1 - u0)
    vs = v0 + (np.arange(n) + 0.5) / n * (v1 - v0)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    ders = s.derivatives(uu.ravel(), vv.ravel(), 1)
    da = np.linalg.norm(np.cross(ders[:, 1, 0], ders[:, 0, 1]), axis=1) * (u1 - u0) * (v1 - v0) / n**2
    c = s.curvatures(uu.ravel(), vv.ravel())
    ell = max(size, 1e-300)
    per_u = np.sqrt(np.abs(c.k1) / (8 * tolerance)) + 1.0 / ell
    per_v = np.sqrt(np.abs(c.k2) / (8 * tolerance)) + 1.0 / ell
    return float(2.0 * np.sum(da * per_u * per_v))


def _check_tolerance(s, tolerance: float, max_triangles: int) -> tuple[float, float]:
    """The surface size and the curvature estimate of the triangle count; refuses tolerances below float64 resolution or needing more than
    ``max_triangles`` by the curvature estimate (before anything large is allocated)."""
    size = model_size(s, samples=17)
    if tolerance < MIN_RELATIVE_TOLERANCE * size:
        raise SurfmodError(
            f"tolerance: {tolerance:g} is below {MIN_RELATIVE_TOLERANCE:g} x the surface size {size:.3g}; "
            "deviations that small cannot be measured in double precision"
        )
    estimate = estimate_triangles(s, tolerance, size)
    if MESH_OVERHEAD * estimate > max_triangles:
        raise SurfmodError(
            f"tolerance: {tolerance:g} would need about {MESH_OVERHEAD * estimate:,.0f} triangles, above the limit "
            f"max_triangles={max_triangles:,}"
        )
    return size, estimate


#: a structured grid with more than this many times the curvature estimate of triangles
#: carries an isolated feature's density across the domain: local refinement is tried too
LOCAL_FEATURE_RATIO = 6.0


def tessellate_surface(s, tolerance: float, max_triangles: int = MAX_TRIANGLES, progress: bool = False,
                       method: str = "auto") -> Mesh:
    """Tessellation of a surfmod surface: ``method="grid"`` is the verified structured
    grid of :mod:`surfmod.meshing.gridmesh`, ``"adaptive"`` the cell refinement of
    :mod:`surfmod.meshing.adaptive`, ``"auto"`` (default) the grid, and the adaptive
    refinement as well where the grid needs more than ``LOCAL_FEATURE_RATIO`` times the
    curvature estimate of triangles (an isolated feature, whose density a tensor grid
    spreads along its lines), keeping the smaller mesh; ``progress`` shows a tqdm bar
    over the refinement passes.

    >>> import surfmod as sm
    >>> m = tessellate_surface(sm.torus(3.0, 1.0), 0.05)
    >>> m.info["kind"], m.info["closed"], m.info["max_deviation"] <= 0.05
    ('grid', (True, True), True)
    """
    size, estimate = _check_tolerance(s, tolerance, max_triangles)
    with tqdm(desc="tessellate", unit="pass", disable=not progress, leave=False) as bar:
        if method == "grid":
            return _grid_mesh(s, tolerance, max_triangles, size, bar)
        if method == "adaptive":
            return _adaptive_mesh(s, tolerance, max_triangles, bar)
        try:
            grid = _grid_mesh(s, tolerance, max_triangles, size, bar)
        except SurfmodError:
            grid = None  # e.g. over max_triangles as a tensor grid: local refinement may fit
        if grid is not None and len(grid.faces) <= LOCAL_FEATURE_RATIO * estimate:
            return grid
        try:
            local = _adaptive_mesh(s, tolerance, max_triangles, bar)
        except SurfmodError:
            if grid is None:
                raise
            return grid
        return local if grid is None or len(local.faces) < len(grid.faces) else grid


def _grid_mesh(s, tolerance: float, max_triangles: int, size: float, bar) -> Mesh:
    sides = domain_sides(s, size)
    verts, faces, uv, dev, passes = grid_tessellate(s, tolerance, max_triangles, sides, bar)
    info = {
        "kind": "grid",
        "tolerance": tolerance,
        "max_deviation": dev,
        "triangles": len(faces),
        "samples_per_triangle": len(DENSE),
        "iterations": passes,
        "closed": (sides[1], sides[2]),
        "uv": uv,
    }
    return Mesh(verts, faces, info)


def _adaptive_mesh(s, tolerance: float, max_triangles: int, bar) -> Mesh:
    # analytic surfaces start from a uniform grid sized by curvature; whether the exact
    # count or half of it (per direction, completed by dyadic refinement) lands closer to
    # the need depends on the surface, so both are tried and the smaller mesh is kept
    best = None
    for scale in (1.0,) if getattr(s, "knots", None) is not None else (1.0, 2.0):
        ref = Refiner(s, tolerance, max_triangles, scale, bar)
        tris, dev, stuck = ref.run()
        if best is None or len(tris) < len(best[1]):
            best = (ref, tris, dev, stuck)
    ref, tris, dev, stuck = best
    if dev.size and dev.max() > tolerance:
        raise SurfmodError(
            f"tolerance: {tolerance:g} not reached: measured {dev.max():.3g} after {ref.iterations} refinement "
            f"passes ({stuck} cells could not be split further)"
        )
    flat = tris.reshape(-1, 2)
    cx, cy = shared_points(flat[:, 0], flat[:, 1], ref.lat.X, ref.lat.Y, ref.sides)
    keys = ref._key(cx, cy)
    unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    faces = inverse.reshape(-1, 3)
    uv = ref.lat.uv(cx[first], cy[first])
    verts = s._derivatives(uv[:, 0], uv[:, 1], 0)[:, 0, 0]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    info = {
        "kind": "adaptive",
        "tolerance": tolerance,
        "max_deviation": float(dev.max()) if dev.size else 0.0,
        "triangles": int(keep.sum()),
        "samples_per_triangle": len(DENSE),
        "iterations": ref.iterations,
        "closed": (ref.closed_u, ref.closed_v),
        "uv": uv,
    }
    return Mesh(verts, faces[keep], info)


#: default cap for surfmod surfaces (the adaptive refinement, tried on surfaces with an
#: isolated feature, meshes a few thousand triangles per second in NumPy): a cap of
#: 250,000 is a few minutes at most
MAX_SURFACE_TRIANGLES = 250_000


def tessellate(obj, tolerance: float, *, max_triangles: int | None = None, strict: bool = False,
               progress: bool = False, method: str = "auto") -> Mesh:
    """Triangle mesh of a surfmod surface or a build123d shape whose chordal deviation
    from the exact geometry is at most ``tolerance`` -- measured on 25 sample points per
    triangle and reported in ``info["max_deviation"]``.

    Surfaces are meshed by ``method="grid"``: a structured grid whose u- and v-lines
    are placed where curvature needs them, verified on every triangle and refined until
    it passes (:mod:`surfmod.meshing.gridmesh`), or ``method="adaptive"``: cells refined
    locally (fewer triangles around isolated features, several times slower).  The
    default ``"auto"`` takes the grid, and also tries the adaptive refinement when the
    grid needs many times the triangles the curvature predicts (an isolated feature),
    keeping the smaller mesh.  A tolerance that cannot be reached raises
    ``SurfmodError``.  Shapes (solids, STEP parts) go through
    BRepMesh, measured face by face; where a face of the model is itself off by more than
    ``tolerance`` (its edges' curves stray from the face within their declared
    tolerance), the mesh is still written and the face is listed in
    ``info["faces_over_tolerance"]``, or refused with ``strict=True``
    (:func:`surfmod.meshing.brep.tessellate_shape`).  ``progress`` shows a tqdm bar.
    A tolerance <= 0, or one so small that more than ``max_triangles`` triangles would
    be needed, raises ``SurfmodError`` before anything large is allocated.
    The default cap is ``MAX_SURFACE_TRIANGLES`` (250,000) for surfmod surfaces and
    ``MAX_TRIANGLES`` (5,000,000) for shapes meshed by BRepMesh.

    >>> import surfmod as sm, numpy as np
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> net[1, 1, 2] = 2.0
    >>> m = sm.tessellate(sm.BezierSurface(net), 0.01)
    >>> m.info["max_deviation"] <= 0.01
    True
    """
    tolerance = checks.positive(tolerance, "tolerance")
    if max_triangles is None:
        max_triangles = MAX_SURFACE_TRIANGLES if isinstance(obj, Surface) else MAX_TRIANGLES
    max_triangles = checks.count(max_triangles, "max_triangles", minimum=2)
    if method not in ("auto", "grid", "adaptive"):
        raise SurfmodError(f"method: expected 'auto', 'grid' or 'adaptive', got {method!r}")
    if isinstance(obj, Surface):
        return tessellate_surface(obj, tolerance, max_triangles, progress, method)
    if isinstance(obj, Mesh):
        raise SurfmodError("obj: is already a Mesh")
    shape = getattr(obj, "wrapped", obj)
    if not hasattr(shape, "ShapeType") or shape.IsNull():
        raise SurfmodError(f"obj: expected a surfmod surface or a build123d shape, got {type(obj).__name__}")
    return tessellate_shape(shape, tolerance, max_triangles, strict=strict, progress=progress)
