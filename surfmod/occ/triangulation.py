"""OCCT's side of CAM: the part as one fine triangle soup for the drop-cutter.

Every face of the shape is triangulated by ``BRepMesh_IncrementalMesh``; its triangles lie
inside the face's trim (BRepMesh meshes the face, not its untrimmed surface) and their
nodes lie on the exact surface.  The plain loops here run over OCCT calls (one per node
or triangle): this is the kernel boundary, not a NumPy evaluation path.
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from .mesh import mesh_faces
from .topo import wrapped


def part_triangles(shape, deflection: float, angular: float = 0.35, *, face_index: bool = False):
    """``(triangles (M, 3, 3), deflection)``: all faces of ``shape`` meshed by BRepMesh at
    the linear ``deflection`` (model units) and ``angular`` deflection (radians), in global
    coordinates, and the largest chordal deflection BRepMesh measured on any face (at least
    the requested one; some faces of real parts cannot be meshed finer than their own
    tolerance allows).  Any triangulation stored on the shape is replaced.  A face BRepMesh
    leaves without triangles raises ``SurfmodError`` (the tool would not see it).  With
    ``face_index`` a third item: the faces (``faces_of`` order) and each triangle's
    index into them ``(M,)``."""

    if wrapped(shape) is None:
        raise SurfmodError(f"obj: expected an OCCT shape, got {type(shape).__name__}")
    blocks, owners, faces = [], [], []
    unmeshed = 0
    measured = float(deflection)
    for _, face, got in mesh_faces(shape, deflection, angular, with_uv=False):
        if got is None:
            unmeshed += 1  # a face the tool cannot see: never skip it silently
            continue
        blocks.append(got.nodes[got.triangles])
        owners.append(np.full(len(got.triangles), len(faces)))
        faces.append(face)
        measured = max(measured, got.deflection)
    if unmeshed:
        raise SurfmodError(f"obj: BRepMesh could not triangulate {unmeshed} face(s); a tool path over them "
                           f"cannot be checked")
    if not blocks:
        raise SurfmodError("obj: has no faces to machine")
    if face_index:
        return np.concatenate(blocks), measured, (faces, np.concatenate(owners))
    return np.concatenate(blocks), measured
