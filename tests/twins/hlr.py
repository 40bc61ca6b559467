"""Hidden-line outlines of faces (``HLRBRep_Algo``): the kernel twin of the silhouettes of
:mod:`surfmod.ops.shadow`."""

from __future__ import annotations

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
from OCP.HLRAlgo import HLRAlgo_Projector
from OCP.HLRBRep import HLRBRep_Algo, HLRBRep_HLRToShape
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from surfmod.occ import arrays
from surfmod.occ.guard import kernel


def hlr_outline(face, direction, samples_per_edge: int = 60):
    """Exact hidden-line removal (``HLRBRep_Algo``) of a face seen along ``direction``
    (parallel projection).  Returns ``(frame, {"outline": [...], "sharp": [...]})``: 2-D
    polylines in the projector frame ``frame = (origin, xdir, ydir)``; ``outline`` holds
    the silhouette (outline) edges, ``sharp`` the projected face boundary, visible and
    hidden alike."""
    d = np.asarray(direction, dtype=float)
    with kernel("HLRBRep_Algo"):
        ax = gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(*map(float, d)))
        frame = (np.zeros(3), arrays.xyz(ax.XDirection()), arrays.xyz(ax.YDirection()))
        algo = HLRBRep_Algo()
        algo.Add(getattr(face, "wrapped", face))
        algo.Projector(HLRAlgo_Projector(ax))
        algo.Update()
        algo.Hide()
        to_shape = HLRBRep_HLRToShape(algo)
        groups = {
            "outline": [to_shape.OutLineVCompound(), to_shape.OutLineHCompound()],
            "sharp": [to_shape.VCompound(), to_shape.HCompound()],
        }
        result = {}
        for key, shapes in groups.items():
            polylines = []
            for shape in shapes:
                if shape is None or shape.IsNull():
                    continue
                explorer = TopExp_Explorer(shape, TopAbs_EDGE)
                while explorer.More():
                    curve = BRepAdaptor_Curve(TopoDS.Edge(explorer.Current()))
                    ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), samples_per_edge)
                    polylines.append(np.array([arrays.xyz(curve.Value(float(t)))[:2] for t in ts]))
                    explorer.Next()
            result[key] = polylines
    return frame, result
