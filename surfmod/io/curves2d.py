"""Gather polylines for the 2-D exporters (DXF, SVG) from sections, curves or arrays.

A section is recognized by what it offers (``polylines_2d`` and ``closed``), not by its
class, so this low-level module does not depend on ``surfmod.uses``.
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..curve import Curve
from ..errors import SurfmodError


def is_section(item) -> bool:
    """True for objects shaped like :class:`surfmod.uses.section.Section`."""
    return hasattr(item, "polylines_2d") and hasattr(item, "closed") and hasattr(item, "wires")


def polylines_of(obj, name: str = "curves", samples: int = 128, tolerance: float | None = None):
    """``(polylines, closed)``: a section gives its curves in the plane frame ``(N, 2)``
    (within ``tolerance`` of the exact edges when given); surfmod curves are sampled in
    3-D; arrays ``(N, 2)`` or ``(N, 3)`` pass through.  Lists may mix these."""
    items = obj if isinstance(obj, (list, tuple)) else [obj]
    polys, closed = [], []
    for k, item in enumerate(items):
        if is_section(item):
            polys.extend(item.polylines_2d(tolerance))
            closed.extend(item.closed)
        elif isinstance(item, Curve):
            t0, t1 = item.domain
            p = item.points(np.linspace(t0, t1, samples))
            polys.append(p)
            closed.append(bool(np.allclose(p[0], p[-1], atol=1e-9)))
        else:
            arr = checks.finite_array(item, f"{name}[{k}]", ndim=2)
            if arr.shape[1] not in (2, 3) or len(arr) < 2:
                raise SurfmodError(f"{name}[{k}]: expected a polyline of shape (N >= 2, 2 or 3), got {arr.shape}")
            polys.append(arr)
            closed.append(bool(np.allclose(arr[0], arr[-1], atol=1e-12)))
    if not polys:
        raise SurfmodError(f"{name}: nothing to export (empty section or list)")
    return polys, closed
