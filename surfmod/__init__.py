"""surfmod: the surface-modeling toolbox of CAD/CAM on OpenCASCADE, checked by NumPy.

>>> import surfmod as sm
>>> s = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
>>> sm.crosscheck(s).passed
True

Public names are resolved lazily so that ``import surfmod`` stays fast; OCP and
build123d load on the first call that needs the kernel.
"""

from __future__ import annotations

import importlib

from .errors import KernelError, SurfmodError

__version__ = "0.1.0"

# public name -> module that defines it (relative to this package)
_EXPORTS = {
    "Surface": ".surface",
    "Curve": ".curve",
    "Curvatures": ".eval.differential",
    "BSplineSurface": ".nets.bspline",
    "BSplineCurve": ".nets.bspline",
    "BezierSurface": ".nets.bezier",
    "BezierCurve": ".nets.bezier",
    "HermiteBicubic": ".nets.hermite",
    "plane": ".build.plane",
    "PlaneSurface": ".build.plane",
    "Line": ".build.curves",
    "Circle": ".build.conics",
    "Arc": ".build.conics",
    "Ellipse": ".build.conics",
    "LineCurve": ".build.conics",
    "Parabola": ".build.conics",
    "Hyperbola": ".build.conics",
    "ruled": ".build.ruled",
    "RuledSurface": ".build.ruled",
    "tabulated_cylinder": ".build.extrusion",
    "TabulatedCylinder": ".build.extrusion",
    "revolution": ".build.revolution",
    "RevolutionSurface": ".build.revolution",
    "AnalyticPlane": ".build.elementary",
    "CylindricalSurface": ".build.elementary",
    "ConicalSurface": ".build.elementary",
    "SphericalSurface": ".build.elementary",
    "ToroidalSurface": ".build.elementary",
    "sphere": ".build.quadrics",
    "torus": ".build.quadrics",
    "ellipsoid": ".build.quadrics",
    "Ellipsoid": ".build.quadrics",
    "OffsetSurface": ".build.readers_elementary",
    "from_face": ".build.from_face",
    "from_edge": ".build.from_face",
    "crosscheck": ".check",
    "CrossCheck": ".check",
    "Mesh": ".mesh.grid",
    "export_step": ".io.step",
    "import_step": ".io.step",
    "export_stl": ".io.stl",
    "tessellate": ".mesh.tessellate",
    "isocurves": ".mesh.isocurves",
    "IsoCurves": ".mesh.isocurves",
    "IsoCurve": ".mesh.isocurves",
    "render": ".mesh.render",
    "interpolate": ".build.fitting",
    "approximate": ".build.fitting",
    "FittedSurface": ".build.fitting",
    "superellipsoid": ".build.superellipsoid",
    "Superellipsoid": ".build.superellipsoid",
    "explicit": ".build.forms",
    "ExplicitSurface": ".build.forms",
    "implicit": ".build.forms",
    "ImplicitSurface": ".build.forms",
    "to_implicit": ".build.forms",
    "sweep": ".build.sweep",
    "SweptSurface": ".build.sweep",
    "loft": ".build.loft",
    "LoftSurface": ".build.loft",
    "trim": ".ops.trim",
    "trimmed_area": ".ops.trim",
    "intersect": ".ops.intersect",
    "intersect_line": ".ops.intersect",
    "IntersectionCurve": ".ops.intersect",
    "project": ".ops.project",
    "Projection": ".ops.project",
    "shadow": ".ops.shadow",
    "Shadow": ".ops.shadow",
    "catmull_clark": ".subdiv.catmull_clark",
    "loop_subdivide": ".subdiv.loop",
    "catmull_clark_limit": ".subdiv.masks",
    "loop_limit": ".subdiv.masks",
    "LimitPoints": ".subdiv.masks",
    "limit_surface": ".subdiv.limit",
    "LimitSurface": ".subdiv.limit",
    "mass_properties": ".uses.mass",
    "MassProperties": ".uses.mass",
    "interference": ".uses.interference",
    "Interference": ".uses.interference",
    "section": ".uses.section",
    "Section": ".uses.section",
    "export_dxf": ".io.dxf",
    "export_svg": ".io.svg",
    "fe_mesh": ".uses.femesh",
    "FEMesh": ".uses.femesh",
    "export_fe_mesh": ".uses.femesh",
    "toolpath": ".uses.toolpath",
    "Toolpath": ".uses.toolpath",
    "Tool": ".uses.toolpath",
    "export_gcode": ".io.gcode",
    "make_solid": ".uses.inputs",
}

__all__ = sorted([*_EXPORTS, "SurfmodError", "KernelError", "mesh"])

# ``surfmod.mesh`` is both the subpackage with the meshing code and the public function
# ``sm.mesh(s, m, n)``.  Importing the subpackage sets the package attribute, so the
# function is bound right after it (pure NumPy, cheap) and stays the public name.
from .mesh.grid import mesh  # noqa: E402


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'surfmod' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return __all__
