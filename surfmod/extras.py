"""The optional extras: which call needs which package, and the one way to load one.

surfmod's hard dependencies (NumPy, SciPy, numba, OCP, build123d, matplotlib, trimesh,
tqdm, joblib, ezdxf, mpmath) serve the public API and every command's default path;
these come with an extra of ``pyproject.toml`` and serve one call each:

========  ======================  ====================================================
extra     packages                needed by
========  ======================  ====================================================
fem       gmsh, meshio            :func:`surfmod.fe_mesh`, ``surfmod femesh``
interop   geomdl, splipy,         :func:`surfmod.to_geomdl`, :func:`surfmod.to_splipy`,
          rhino3dm                :func:`surfmod.to_rhino` and their inverses
cluster   dask[distributed]       ``surfmod check|mesh PATH... --scheduler ADDRESS``
========  ======================  ====================================================

>>> require("math", "fem", "a test").pi > 3
True
>>> try:
...     require("surely_not_installed_package", "fem", "sm.fe_mesh")
... except MissingExtraError as exc:
...     print(exc)
sm.fe_mesh needs the optional package 'surely_not_installed_package': pip install "surfmod[fem]"
"""

from __future__ import annotations

import importlib

from .errors import MissingExtraError

#: extra -> the top-level modules it brings (pyproject.toml's [project.optional-dependencies])
EXTRAS = {
    "fem": ("gmsh", "meshio"),
    "interop": ("geomdl", "splipy", "rhino3dm"),
    "cluster": ("distributed",),
}


def require(module: str, extra: str, purpose: str):
    """The imported ``module`` (an optional package of ``extra``), or a
    :class:`~surfmod.errors.MissingExtraError` saying that ``purpose`` needs it and which
    extra to install."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(
            f"{purpose} needs the optional package {module.split('.')[0]!r}: pip install \"surfmod[{extra}]\"") from None
