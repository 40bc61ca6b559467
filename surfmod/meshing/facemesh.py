"""A shape's BRepMesh triangulation face by face, with what measuring it needs: each
face's surface, its solid and its isometric repeats (assemblies), and (u, v) nodes
only for the faces not measured in closed form.

BRepMesh itself runs at the kernel door (:func:`surfmod.occ.mesh.mesh_faces`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SurfmodError

#: Surfaces whose distance has a closed form (:mod:`surfmod.meshing.analytic_distance`):
#: their (u, v) nodes are not needed to measure a mesh.
ANALYTIC = ("Geom_Plane", "Geom_CylindricalSurface", "Geom_ConicalSurface", "Geom_SphericalSurface",
            "Geom_ToroidalSurface")


@dataclass
class FaceMesh:
    """One face's BRepMesh triangulation: 3-D ``nodes`` (global coordinates), ``uv``
    nodes on the face's surface, ``triangles`` oriented outwards (face orientation
    applied), the face's ``surface`` (global coordinates, trimmed-surface wrappers
    removed), its ``face``, ``bounds`` (UV box: given, or read on first use; closed-form
    measurement never needs it), ``index`` in exploration order and ``solid`` (index of
    the solid it belongs to, -1 for faces outside any solid) and ``repeats``: the
    position in the same list of an earlier face this one repeats at an isometric
    location (same triangulation, same surface moved rigidly: the same deviations), or
    -1."""

    nodes: np.ndarray
    uv: np.ndarray
    triangles: np.ndarray
    surface: object
    face: object
    uv_box: tuple | None
    index: int = 0
    solid: int = -1
    repeats: int = -1

    @property
    def bounds(self) -> tuple:
        """The face's UV box ``(u0, u1, v0, v1)`` (``BRepTools.UVBounds``)."""
        if self.uv_box is None:
            from ..occ.mesh import uv_box

            self.uv_box = uv_box(self.face)
        return self.uv_box


def brepmesh(shape, deflection: float, angular: float = 0.5, *, relative: bool = False, missing: list | None = None,
             uv_bounds: dict | None = None) -> list[FaceMesh]:
    """Run ``BRepMesh_IncrementalMesh`` (after clearing old triangulations) and return the
    per-face triangulations.  BRepMesh discretizes each edge once, so nodes of faces that
    share an edge coincide bit for bit.  Faces BRepMesh left without triangles are
    skipped; their indices are appended to ``missing`` when a list is given.
    ``uv_bounds``: faces' UV boxes already known (by face hash, from
    :func:`surfmod.meshing.figures.shape_figures`).

    >>> import build123d as bd
    >>> fms = brepmesh(bd.Box(1, 1, 1), 0.1)
    >>> len(fms), len(fms[0].triangles), fms[0].solid
    (6, 2, 0)
    """
    from ..occ.geom import surface_type
    from ..occ.mesh import face_basis, face_solids, mesh_faces
    from ..occ.topo import wrapped

    shp = wrapped(shape)
    surfaces = {}

    def needs_uv(face):
        # analytic faces are measured in closed form, without their (u, v) nodes
        surfaces[face.__hash__()] = surf = face_basis(face)
        return surface_type(surf) not in ANALYTIC

    out = []
    first: dict = {}  # instance group -> position in out of its first rigid face
    meshed = mesh_faces(shp, deflection, angular, relative=relative, with_uv=needs_uv)
    owner = face_solids(shp)
    for k, face, got in meshed:
        if got is None:
            if missing is not None:
                missing.append(k)
            continue
        tri = got.triangles[:, ::-1] if got.reversed else got.triangles
        known = uv_bounds.get(face.__hash__()) if uv_bounds is not None else None
        bounds = None if known is None else tuple(float(b) for b in known)  # else read when needed
        shared = got.rigid and got.instance >= 0
        repeats = first.get(got.instance, -1) if shared else -1
        if shared and got.instance not in first:
            first[got.instance] = len(out)
        out.append(FaceMesh(got.nodes, got.uv, tri, surfaces[face.__hash__()], face, bounds, k,
                            owner.get(face.__hash__(), -1), repeats))
    if not out:
        raise SurfmodError("shape: has no faces to triangulate")
    return out


def concatenated(fms: list) -> tuple:
    """``(nodes, triangles, node offsets, triangle offsets)`` of many face meshes end to
    end, the triangles indexing the joined nodes."""
    node_at = np.cumsum([0] + [len(fm.nodes) for fm in fms])
    tri_at = np.cumsum([0] + [len(fm.triangles) for fm in fms])
    triangles = np.concatenate([fm.triangles + o for fm, o in zip(fms, node_at)])
    return np.concatenate([fm.nodes for fm in fms]), triangles, node_at, tri_at
