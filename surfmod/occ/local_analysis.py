"""OCCT's side of continuity analysis: ``LocalAnalysis_SurfaceContinuity`` at given
parameter pairs, and the edges a shell's faces share, sampled through their p-curves.

Plain loops over OCCT calls: these are references and topology walks, not evaluation
paths.
"""

from __future__ import annotations

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_G2
from OCP.LocalAnalysis import LocalAnalysis_SurfaceContinuity
from OCP.TopAbs import TopAbs_EDGE, TopAbs_IN
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt2d, gp_Vec2d

from .guard import kernel
from .topo import explore, faces_of, geometric_edges, wrapped


def _pcurve_samples(edge, face, samples: int):
    """``(uv, tangent)``: ``samples`` points of the edge's p-curve on ``face`` and its
    (u, v) tangents, evenly in the p-curve's parameter."""
    pcurve = BRepAdaptor_Curve2d(edge, face)
    t = np.linspace(pcurve.FirstParameter(), pcurve.LastParameter(), samples)
    uv, tangent = np.empty((samples, 2)), np.empty((samples, 2))
    p, d = gp_Pnt2d(), gp_Vec2d()
    for k, tk in enumerate(t):  # OCCT's per-point D1: a sampler, not an evaluation path
        pcurve.D1(float(tk), p, d)
        uv[k] = (p.X(), p.Y())
        tangent[k] = (d.X(), d.Y())
    return uv, tangent

def local_analysis(geom_a, uv_a: np.ndarray, geom_b, uv_b: np.ndarray, *, reverse_b: bool = False) -> np.ndarray:
    """``(N, 3)``: OCCT's ``C0Value``, ``G1Angle`` and ``G2CurvatureGap`` at each pair of
    parameters (NaN where OCCT reports the analysis not done, e.g. undefined curvature).

    OCCT folds the normal angle into ``[0, pi/2]`` and its curvature gap mixes the mean
    and the half-difference of the principal curvatures
    (``|dH| + sqrt(dZ^2 cos^2 a + Z^2 sin^2 a)``, ``Z`` the mean half-difference, ``a``
    the angle between averaged principal directions): for a plane tangent to a cylinder
    of radius ``R`` it is ``1/(2R)``.  The gap takes both curvatures against each
    surface's own normal, so for oppositely oriented surfaces ``reverse_b=True`` hands
    OCCT ``b``'s ``UReversed`` copy (at the mapped parameters) instead.
    """
    out = np.full((len(uv_a), 3), np.nan)
    with kernel("LocalAnalysis_SurfaceContinuity"):
        if reverse_b:
            uv_b = np.array([(geom_b.UReversedParameter(float(u)), v) for u, v in uv_b])
            geom_b = geom_b.UReversed()
        for i, ((ua, va), (ub, vb)) in enumerate(zip(uv_a, uv_b)):
            la = LocalAnalysis_SurfaceContinuity(
                geom_a, float(ua), float(va), geom_b, float(ub), float(vb), GeomAbs_G2)
            if la.IsDone():
                out[i] = (la.C0Value(), la.G1Angle(), la.G2CurvatureGap())
    return out


def _inside_sign(face, uv, direction, step) -> float:
    """+1 when ``uv + step * direction`` lies inside the face, -1 when the opposite side
    does (``BRepClass_FaceClassifier``); 0 when neither (a sliver)."""
    for sign in (1.0, -1.0):
        p = uv + sign * step * direction
        state = BRepClass_FaceClassifier(face, gp_Pnt2d(float(p[0]), float(p[1])), 1e-9).State()
        if state == TopAbs_IN:
            return sign
    return 0.0


def shared_edges(shape, samples: int) -> list[dict]:
    """Every non-degenerate edge of ``shape`` bounding exactly two different faces.

    Each record: ``edge`` (index in the edge map), ``faces`` (indices into
    :func:`surfmod.occ.topo.faces_of`), ``face_shapes``, and per face ``uv`` ``(samples, 2)``
    (the p-curve at the edge's own parameters), ``tangent`` ``(samples, 2)`` (its
    derivative) and ``inward`` ``(samples, 2)``: the unit parameter-space normal of the
    p-curve pointing into that face.
    """
    s = wrapped(shape)
    all_faces = faces_of(s)
    records = []
    with kernel("shared edges (BRepAdaptor_Curve2d)"):
        for index, edge, faces in geometric_edges(s):
            ancestors = []
            for f in faces:
                if not any(f.IsSame(g) for g in ancestors):
                    ancestors.append(f)
            if len(ancestors) != 2:
                continue  # free edges, seams (one face twice), non-manifold edges
            rec = {"edge": index, "faces": [], "face_shapes": [], "uv": [], "tangent": [], "inward": []}
            for face in ancestors:
                rec["faces"].append(next((k for k, g in enumerate(all_faces) if g.IsSame(face)), -1))
                rec["face_shapes"].append(face)
                uv, tangent = _pcurve_samples(edge, face, samples)
                perp = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
                perp /= np.maximum(np.linalg.norm(perp, axis=1, keepdims=True), 1e-300)
                u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
                step = 1e-4 * max(u1 - u0, v1 - v0)
                mid = samples // 2
                sign = _inside_sign(face, uv[mid], perp[mid], step) or 1.0
                rec["uv"].append(uv)
                rec["tangent"].append(tangent)
                rec["inward"].append(sign * perp)
            records.append(rec)
    return records


def face_edges_uv(face, samples: int) -> list:
    """Every non-degenerate edge of one face as ``(uv (samples, 2), tangent (samples, 2))``
    through its p-curve on that face."""
    f = TopoDS.Face(wrapped(face))
    out = []
    with kernel("face edges (BRepAdaptor_Curve2d)"):
        for edge in (TopoDS.Edge(e) for e in explore(f, TopAbs_EDGE)):
            if not BRep_Tool.Degenerated_s(edge):
                out.append(_pcurve_samples(edge, f, samples))  # (uv, tangent)
    return out
