"""DXF export of section curves (exact LINE/ARC/CIRCLE/SPLINE entities) and polylines (ezdxf), atomic."""

from __future__ import annotations

import ezdxf

from ..errors import SurfmodError
from ..atomic import atomic_path, target_path
from .curves2d import is_section, polylines_of


def _xy(p):
    return (float(p[0]), float(p[1]))


def _add_entity(msp, entity, attribs) -> None:
    kind = entity[0]
    if kind == "line":
        msp.add_line(_xy(entity[1]), _xy(entity[2]), dxfattribs=attribs)
    elif kind == "circle":
        msp.add_circle(_xy(entity[1]), float(entity[2]), dxfattribs=attribs)
    elif kind == "arc":
        _, center, r, a0, a1 = entity
        msp.add_arc(_xy(center), float(r), float(a0), float(a1), dxfattribs=attribs)
    elif kind == "spline":
        _, degree, ctrl, knots, weights = entity
        pts = [(float(x), float(y), 0.0) for x, y in ctrl]
        k = [float(t) for t in knots]
        if weights is None:
            msp.add_open_spline(pts, degree=int(degree), knots=k, dxfattribs=attribs)
        else:
            msp.add_rational_spline(pts, [float(w) for w in weights], degree=int(degree), knots=k, dxfattribs=attribs)
    else:  # pragma: no cover - entities_2d only makes the kinds above
        raise SurfmodError(f"curves: unknown section entity {kind!r}")


def export_dxf(curves, path, *, layer: str = "SECTION") -> int:
    """Write section curves to a DXF file and return the number of entities written.

    A :class:`~surfmod.uses.section.Section` is written in its plane frame with exact
    entities: ``LINE``, ``ARC``, ``CIRCLE`` and ``SPLINE`` (B-spline edges with their own
    knots and weights; other curves in their exact B-spline form), one per edge.
    Surfmod curves and ``(N, 2|3)`` polylines become ``LWPOLYLINE`` / 3-D ``POLYLINE``
    entities, closed ones flagged closed.

    >>> import surfmod as sm, build123d as bd, tempfile, os, ezdxf
    >>> path = os.path.join(tempfile.mkdtemp(), "s.dxf")
    >>> sm.export_dxf(sm.section(bd.Cylinder(2, 3), (0, 0, 0), (0, 0, 1)), path)
    1
    >>> ezdxf.readfile(path).modelspace().query("CIRCLE")[0].dxf.radius
    2.0
    """
    target = target_path(path, "path", (".dxf",))
    items = curves if isinstance(curves, (list, tuple)) else [curves]
    doc = ezdxf.new("R2010", setup=True)
    doc.units = 4  # millimetres
    if layer not in doc.layers:
        doc.layers.add(layer)
    msp = doc.modelspace()
    attribs = {"layer": layer}
    count = 0
    rest = []
    for item in items:
        if is_section(item):
            for wire in item.entities_2d():
                for entity in wire:
                    _add_entity(msp, entity, attribs)
                    count += 1
        else:
            rest.append(item)
    if rest or not count:
        polys, closed = polylines_of(rest if rest else items)
        for p, c in zip(polys, closed):
            pts = p[:-1] if c else p
            if p.shape[1] == 2:
                msp.add_lwpolyline([tuple(map(float, q)) for q in pts], close=c, dxfattribs=attribs)
            else:
                msp.add_polyline3d([tuple(map(float, q)) for q in pts], close=c, dxfattribs=attribs)
            count += 1
    with atomic_path(target) as tmp:
        doc.saveas(tmp)
    return count
