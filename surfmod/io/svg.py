"""SVG export of section curves (2-D projection into the section plane's frame), atomic."""

from __future__ import annotations

import numpy as np

from .. import checks
from ..atomic import atomic_path, target_path
from .curves2d import is_section, polylines_of


def _default_tolerance(curves):
    """1e-4 of the diagonal of the sections' bounding boxes (None without sections)."""
    items = curves if isinstance(curves, (list, tuple)) else [curves]
    sizes = [float(np.ptp(np.concatenate(c.polylines), axis=0).max()) for c in items if is_section(c) and c.polylines]
    return 1e-4 * max(sizes) if sizes else None


def export_svg(curves, path, *, tolerance: float | None = None, stroke: float | None = None, margin: float = 0.05) -> int:
    """Write section curves to an SVG drawing.

    A :class:`~surfmod.uses.section.Section` is drawn in its plane frame (plane x to
    the right, plane y up) as polylines whose chords stay within ``tolerance`` of the
    exact edges (default: 1e-4 of the section's size; the value is stated in the file's
    ``<desc>``); 3-D polylines are projected onto their own XY plane.
    The drawing is in model units (``viewBox``), one ``<path>`` per curve.
    Returns the number of curves written.

    >>> import surfmod as sm, build123d as bd, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "s.svg")
    >>> sm.export_svg(sm.section(bd.Sphere(2), (0, 0, 0), (1, 0, 0)), path)
    1
    """
    target = target_path(path, "path", (".svg",))
    margin = checks.finite_array(margin, "margin")
    tolerance = _default_tolerance(curves) if tolerance is None else checks.positive(tolerance, "tolerance")
    polys, closed = polylines_of(curves, tolerance=tolerance)
    flat = [p[:, :2] for p in polys]
    allp = np.concatenate(flat)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    size = float(max(hi - lo)) or 1.0
    pad = float(margin) * size
    lo, hi = lo - pad, hi + pad
    width, height = hi - lo
    sw = stroke if stroke is not None else size / 400.0
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width:.6g}mm" height="{height:.6g}mm" '
        f'viewBox="{lo[0]:.9g} {-hi[1]:.9g} {width:.9g} {height:.9g}">',
        f"<desc>surfmod section; chordal tolerance {tolerance:.6g} model units</desc>" if tolerance else "<desc>surfmod curves</desc>",
        f'<g fill="none" stroke="black" stroke-width="{sw:.6g}" stroke-linejoin="round">',
    ]
    for p, c in zip(flat, closed):
        d = "M " + " L ".join(f"{x:.9g} {-y:.9g}" for x, y in (p[:-1] if c else p)) + (" Z" if c else "")
        parts.append(f'<path d="{d}"/>')
    parts += ["</g>", "</svg>", ""]
    with atomic_path(target) as tmp:
        tmp.write_text("\n".join(parts), encoding="utf-8")
    return len(polys)
