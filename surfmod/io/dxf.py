"""DXF export of section curves and polylines (ezdxf), atomic."""

from __future__ import annotations

from ..atomic import atomic_path, target_path
from .curves2d import polylines_of


def export_dxf(curves, path, *, layer: str = "SECTION") -> int:
    """Write section curves (a :class:`~surfmod.uses.section.Section`, surfmod curves or
    ``(N, 2|3)`` polylines) to a DXF file: 2-D polylines become ``LWPOLYLINE`` entities
    (a section is written in its plane frame), 3-D ones ``POLYLINE`` 3-D entities.
    Closed curves are flagged closed.  Returns the number of entities written.

    >>> import surfmod as sm, build123d as bd, tempfile, os, ezdxf
    >>> path = os.path.join(tempfile.mkdtemp(), "s.dxf")
    >>> sm.export_dxf(sm.section(bd.Box(2, 3, 4), (0, 0, 0), (0, 0, 1)), path)
    1
    >>> ezdxf.readfile(path).modelspace().query("LWPOLYLINE")[0].closed
    True
    """
    try:
        import ezdxf
    except ImportError:  # pragma: no cover
        from ..errors import SurfmodError

        raise SurfmodError("path: DXF export needs ezdxf (pip install ezdxf)") from None
    target = target_path(path, "path", (".dxf",))
    polys, closed = polylines_of(curves)
    doc = ezdxf.new("R2010", setup=True)
    doc.units = 4  # millimetres
    if layer not in doc.layers:
        doc.layers.add(layer)
    msp = doc.modelspace()
    for p, c in zip(polys, closed):
        pts = p[:-1] if c else p
        if p.shape[1] == 2:
            msp.add_lwpolyline([tuple(map(float, q)) for q in pts], close=c, dxfattribs={"layer": layer})
        else:
            msp.add_polyline3d([tuple(map(float, q)) for q in pts], close=c, dxfattribs={"layer": layer})
    with atomic_path(target) as tmp:
        doc.saveas(tmp)
    return len(polys)
