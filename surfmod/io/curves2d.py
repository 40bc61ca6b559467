"""Gather polylines for the 2-D exporters (DXF, SVG) from sections, curves or arrays."""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError


def polylines_of(obj, name: str = "curves", samples: int = 128) -> tuple[list[np.ndarray], list[bool]]:
    """``(polylines, closed)``: a :class:`~surfmod.uses.section.Section` gives its curves in
    the plane frame ``(N, 2)``; surfmod curves are sampled in 3-D; arrays ``(N, 2)`` or
    ``(N, 3)`` pass through.  Lists may mix these."""
    from ..curve import Curve
    from ..uses.section import Section

    items = obj if isinstance(obj, (list, tuple)) else [obj]
    polys, closed = [], []
    for k, item in enumerate(items):
        if isinstance(item, Section):
            polys.extend(item.polylines_2d())
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
