"""DESIGN.md rule 1: only surfmod/occ/ imports OCP; nets/ and eval/ are pure NumPy;
``import surfmod`` loads no kernel, and every lecture entity evaluates without one."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "surfmod"


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def _walk(tree, module_level_only: bool):
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if module_level_only and isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        stack.extend(ast.iter_child_nodes(node))


def _imported_modules(path: Path, package_root: Path = PACKAGE.parent, module_level_only: bool = False):
    """Absolute names of every module ``path`` imports, relative imports resolved
    (``from ..occ import geom`` in surfmod/ops/x.py is ``surfmod.occ.geom``); with
    ``module_level_only`` the imports inside functions (lazy doors) are left out."""
    tree = ast.parse(path.read_text(), filename=str(path))
    rel = path.relative_to(package_root).with_suffix("")
    package = list(rel.parts[:-1])
    for node in _walk(tree, module_level_only):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                yield node.module, node.lineno
                continue
            base = package[: len(package) - (node.level - 1)]
            if node.module:
                yield ".".join([*base, node.module]), node.lineno
            else:
                for alias in node.names:
                    yield ".".join([*base, alias.name]), node.lineno


def test_only_occ_imports_ocp():
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        if path.relative_to(PACKAGE).parts[0] == "occ":
            continue
        for module, line in _imported_modules(path):
            if module == "OCP" or module.startswith("OCP."):
                offenders.append(f"{path.relative_to(PACKAGE.parent)}:{line} imports {module}")
    assert not offenders, "OCP imported outside surfmod/occ/:\n" + "\n".join(offenders)


def test_layering_test_detects_a_violation(tmp_path):
    pkg = tmp_path / "surfmod" / "nets"
    pkg.mkdir(parents=True)
    bad = pkg / "bad.py"
    bad.write_text("def f():\n    from OCP.gp import gp_Pnt\n    from ..occ.geom import x\n    from . import y\n")
    found = sorted(m for m, _ in _imported_modules(bad, tmp_path))
    assert found == ["OCP.gp", "surfmod.nets.y", "surfmod.occ.geom"]
    assert not list(_imported_modules(bad, tmp_path, module_level_only=True))


def test_nets_and_eval_are_pure_numpy():
    # The kernel libraries never; surfmod's kernel-side packages only lazily, inside the
    # geom()/face() doors, never at module level.
    kernel = ("build123d", "cadquery", "OCP")
    upper = ("surfmod.occ", "surfmod.construct", "surfmod.uses", "surfmod.ops", "surfmod.io")
    offenders = []
    for sub in ("nets", "eval"):
        for path in (PACKAGE / sub).rglob("*.py"):
            everywhere = [(m, line) for m, line in _imported_modules(path) if m.startswith(kernel)]
            top = [(m, line) for m, line in _imported_modules(path, module_level_only=True) if m.startswith(upper)]
            for module, line in everywhere + top:
                    offenders.append(f"{path.relative_to(PACKAGE.parent)}:{line} imports {module}")
    assert not offenders, "\n".join(offenders)


# Every lecture entity the gallery builds without OCCT, evaluated with OCP and build123d
# made unimportable: the NumPy side must stand on its own (geom()/face() are the only doors).
_NO_KERNEL = """
import sys, importlib.abc
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("OCP", "build123d", "cadquery"):
            raise ImportError(f"blocked: {name}")
sys.meta_path.insert(0, Block())
import numpy as np, surfmod as sm
net = np.stack([*np.meshgrid(np.linspace(0, 3, 4), np.linspace(0, 2, 4), indexing="ij"), np.zeros((4, 4))], -1)
net[1:3, 1, 2] = 1.0
line = sm.Line((0, 0, 0), (0, 0, 2))
arc = sm.Arc((0, 0, 0), (0, 0, 1), 2.0, 0.0, 90.0)
entities = [
    sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)),
    sm.BezierSurface(net), sm.BezierSurface(net, np.linspace(1, 2, 16).reshape(4, 4)),
    sm.BSplineSurface(net, (2, 1)), sm.BSplineSurface.uniform_cubic(net),
    sm.HermiteBicubic(np.zeros((2, 2, 3)) + [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 1]]],
                      np.ones((2, 2, 3)), np.ones((2, 2, 3)), np.zeros((2, 2, 3))),
    sm.ruled(arc, arc.translated((0, 0, 3))), sm.tabulated_cylinder(arc, (0, 0, 1), 4.0),
    sm.revolution(sm.Line((1, 0, 0), (2, 0, 3)), (0, 0, 0), (0, 0, 1), 270.0),
    sm.sphere(2.0), sm.ellipsoid(1, 2, 3), sm.torus(3, 1), sm.superellipsoid(1, 2, 3, 0.5, 2.0),
    sm.explicit(lambda x, y: x * y, (0, 1), (0, 1), 1e-4),
    sm.interpolate(net, (2, 1)),
]
for s in entities:
    (u0, u1), (v0, v1) = s.domain
    u, v = np.linspace(u0, u1, 7), np.linspace(v0, v1, 5)
    assert np.isfinite(s.grid(u, v)).all() and np.isfinite(s.derivatives(u[:5], v, 2)).all(), s
    assert np.isfinite(s.curvatures(u[1:-1, None], v[None, 1:-1]).mean).all(), s
sm.catmull_clark(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.]]), [[0, 1, 2, 3]], 2)
print(len(entities), "OCP" in sys.modules, "build123d" in sys.modules)
"""


def test_every_entity_evaluates_with_the_kernel_blocked():
    out = subprocess.run([sys.executable, "-c", _NO_KERNEL], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    assert out.stdout.split() == ["15", "False", "False"]


def test_import_surfmod_loads_no_kernel():
    # (its time is measured by the benchmarks, not asserted here)
    code = "import sys, surfmod; print('OCP' in sys.modules, 'build123d' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "False"], "import surfmod must not load OCP/build123d"


def test_no_subpackage_shadows_a_public_name():
    # importing every module binds submodules as package attributes: none may hide a
    # public function or class of the same name (sm.mesh once did)
    import importlib
    import pkgutil
    import types

    import surfmod as sm

    for info in pkgutil.walk_packages(sm.__path__, "surfmod."):
        if info.name.endswith("__main__"):
            continue
        importlib.import_module(info.name)
    shadowed = [name for name in sm.__all__ if isinstance(getattr(sm, name), types.ModuleType)]
    assert not shadowed
