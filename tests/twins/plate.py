"""OCCT's ``GeomPlate`` surface through scattered points: the benchmark's reference beside
surfmod's scattered-point fit (``benchmarks/bench_fit.py``)."""

from __future__ import annotations

import numpy as np
from OCP.GeomPlate import GeomPlate_BuildPlateSurface, GeomPlate_MakeApprox, GeomPlate_PointConstraint
from OCP.gp import gp_Pnt

from surfmod.errors import KernelError
from surfmod.occ.guard import kernel


def plate_through_points(points: np.ndarray, degree: int = 3, max_segments: int = 9, tolerance: float = 1e-3):
    """OCCT's ``GeomPlate`` surface constrained by points (``GeomPlate_BuildPlateSurface``
    with ``GeomPlate_PointConstraint``s, approximated by ``GeomPlate_MakeApprox``)."""
    with kernel("GeomPlate_BuildPlateSurface"):
        build = GeomPlate_BuildPlateSurface(degree, 15, 2)
        for x, y, z in np.asarray(points, dtype=float).tolist():
            build.Add(GeomPlate_PointConstraint(gp_Pnt(x, y, z), 0))
        build.Perform()
        if not build.IsDone():
            raise KernelError("GeomPlate_BuildPlateSurface: failed")
        approx = GeomPlate_MakeApprox(build.Surface(), float(tolerance), max_segments, 8, float(tolerance) * 10, 0)
        return approx.Surface()
