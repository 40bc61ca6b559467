"""The door from surfaces, curves and meshes to the renderer: what their ``_repr_png_`` calls.

The renderer (:mod:`surfmod.meshing.render`) ranks above the protocols it draws, so they
cannot import it; the package's ``__init__`` (the top of the rank table) installs it here
when ``surfmod`` is imported, and a notebook that shows a surface, a face read back, a
curve or a mesh gets its picture through :func:`repr_png`.

>>> import surfmod as sm
>>> repr_png(sm.sphere(1.0))[:4] == b"\\x89PNG"
True
"""

from __future__ import annotations

_renderer = None


def install(renderer) -> None:
    """Make ``renderer(obj) -> bytes | None`` the one that :func:`repr_png` calls."""
    global _renderer
    _renderer = renderer


def repr_png(obj) -> bytes | None:
    """A small PNG of ``obj`` for IPython's ``_repr_png_``, or ``None`` (IPython then shows
    the text repr) when no renderer is installed or ``obj`` cannot be drawn."""
    return None if _renderer is None else _renderer(obj)
