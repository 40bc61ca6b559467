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

from .errors import DamagedFileError, InsideOutWarning, KernelError, MissingExtraError, RoundTripWarning, SurfmodError
from .pictures import install as _install_renderer
from .version import installed_version

# public name -> module that defines it (relative to this package)
_EXPORTS = {
    "Surface": ".surface",
    "Curve": ".curve",
    "Curvatures": ".eval.differential",
    "set_threads": ".eval.threads",
    "BSplineSurface": ".nets.bspline",
    "BSplineCurve": ".nets.bspline",
    "BezierSurface": ".nets.bezier",
    "BezierCurve": ".nets.bezier",
    "HermiteBicubic": ".nets.hermite",
    "plane": ".construct.plane",
    "ThreePointPlane": ".construct.plane",
    "Line": ".construct.curves",
    "Circle": ".construct.conics",
    "Arc": ".construct.conics",
    "Ellipse": ".construct.conics",
    "Parabola": ".construct.conics",
    "Hyperbola": ".construct.conics",
    "ruled": ".construct.ruled",
    "RuledSurface": ".construct.ruled",
    "tabulated_cylinder": ".construct.extrusion",
    "TabulatedCylinder": ".construct.extrusion",
    "revolution": ".construct.revolution",
    "RevolutionSurface": ".construct.revolution",
    "PlaneSurface": ".construct.elementary",
    "CylindricalSurface": ".construct.elementary",
    "ConicalSurface": ".construct.elementary",
    "SphericalSurface": ".construct.elementary",
    "ToroidalSurface": ".construct.elementary",
    "sphere": ".construct.quadrics",
    "torus": ".construct.quadrics",
    "ellipsoid": ".construct.quadrics",
    "Ellipsoid": ".construct.quadrics",
    "OffsetSurface": ".construct.offset_surface",
    "from_face": ".readback",
    "TrimmedFace": ".readback",
    "from_edge": ".construct.from_edge",
    "crosscheck": ".occt_crosscheck",
    "CrossCheck": ".occt_crosscheck",
    "Mesh": ".meshing.grid",
    "mesh": ".meshing.grid",
    "export_step": ".io.step_iges",
    "import_step": ".io.step_iges",
    "export_stl": ".io.stl",
    "tessellate": ".meshing.tessellate",
    "isocurves": ".meshing.isocurves",
    "IsoCurves": ".meshing.isocurves",
    "IsoCurve": ".meshing.isocurves",
    "render": ".meshing.render",
    "interpolate": ".construct.fitting",
    "approximate": ".construct.fitting",
    "FittedSurface": ".construct.fitting",
    "superellipsoid": ".construct.superellipsoid",
    "Superellipsoid": ".construct.superellipsoid",
    "explicit": ".construct.forms",
    "ExplicitSurface": ".construct.forms",
    "implicit": ".construct.forms",
    "ImplicitSurface": ".construct.forms",
    "to_implicit": ".construct.forms",
    "sweep": ".construct.sweep",
    "SweptSurface": ".construct.sweep",
    "loft": ".construct.loft",
    "LoftSurface": ".construct.loft",
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
    "boundary_ambiguity": ".uses.mass",
    "MassProperties": ".mass.totals",
    "interference": ".uses.interference",
    "Interference": ".uses.interference",
    "section": ".uses.section",
    "Section": ".uses.section",
    "export_dxf": ".io.dxf",
    "export_svg": ".io.svg",
    "fe_mesh": ".uses.femesh",
    "FEMesh": ".uses.femesh",
    "export_fe_mesh": ".uses.femesh",
    "toolpath": ".cam.toolpath",
    "Toolpath": ".cam.toolpath",
    "Tool": ".cam.tool",
    "Machine": ".cam.machine_table",
    "machine": ".cam.job",
    "Job": ".cam.job",
    "Rough": ".cam.job",
    "Finish": ".cam.job",
    "Rest": ".cam.job",
    "Operation": ".cam.job",
    "export_gcode": ".cam.gcode",
    "make_solid": ".inputs",
    "coons": ".construct.coons",
    "CoonsSurface": ".construct.coons",
    "gordon": ".construct.gordon",
    "GordonSurface": ".construct.gordon",
    "to_build123d": ".io.viewer",
    "to_geomdl": ".interop.geomdl_io",
    "from_geomdl": ".interop.geomdl_io",
    "to_splipy": ".interop.splipy_io",
    "from_splipy": ".interop.splipy_io",
    "to_rhino": ".interop.rhino_io",
    "from_rhino": ".interop.rhino_io",
    "export_iges": ".io.step_iges",
    "import_iges": ".io.step_iges",
    "fit": ".ops.fit",
    "Fit": ".ops.fit",
    "continuity": ".ops.continuity",
    "Continuity": ".ops.continuity",
    "blend": ".ops.blend",
    "BlendSurface": ".ops.blend",
    "analyze": ".meshing.analyze",
    "Analysis": ".meshing.analyze",
    "offset": ".construct.offset",
    "thicken": ".construct.offset",
    "OffsetApproximation": ".construct.offset",
    "fill": ".construct.fill",
    "Fill": ".construct.fill",
    "conformance": ".conform",
    "Conformance": ".conform",
}

__all__ = sorted([*_EXPORTS, "SurfmodError", "KernelError", "DamagedFileError", "MissingExtraError", "RoundTripWarning",
                  "InsideOutWarning"])


def __getattr__(name: str):
    if name == "__version__":
        globals()[name] = value = installed_version()
        return value
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'surfmod' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def _repr_png(obj):
    # the renderer ranks above the surfaces it draws; this package, at the top, hands it to
    # them through surfmod.pictures, loaded (with matplotlib) on the first picture only
    return importlib.import_module(".meshing.render", __name__).repr_png(obj)


_install_renderer(_repr_png)


def __dir__():
    return __all__
