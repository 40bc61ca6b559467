"""DESIGN.md rule 1: only surfmod/occ/ imports OCP; nets/ and eval/ are pure NumPy;
``import surfmod`` loads no kernel, and every lecture entity evaluates without one."""

from __future__ import annotations

import ast
import re
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


# --- lazy imports: only for the kernel and heavy or optional libraries -------------------------
# An import inside a function hides structure, so it needs a reason. Allowed reasons:
#  * a library in LAZY: the kernel (OCP, build123d, cadquery), numba, and libraries that are
#    optional or slow to load (scipy submodules measured 0.25-1.1 s on top of numpy's 0.27 s);
#  * from outside surfmod/occ/, any surfmod.occ module (the geom()/face() doors into the
#    kernel layer), and any surfmod module that loads a LAZY library when imported;
#  * a comment "# cycle: a <-> b" on the import line or the line above, naming the import cycle
#    it breaks.
LAZY = frozenset({
    "OCP", "build123d", "cadquery", "numba", "scipy", "matplotlib", "mpl_toolkits", "gmsh",
    "meshio", "ezdxf", "trimesh", "dask", "distributed", "joblib", "tqdm", "splipy", "geomdl",
    "rhino3dm", "opencamlib", "ocl",
})
CYCLE_MARK = re.compile(r"#\s*cycle:")

def _module_path(module: str, package_root: Path) -> Path | None:
    base = package_root.joinpath(*module.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _resolved(node: ast.Import | ast.ImportFrom, package: list[str], package_root: Path) -> list[str]:
    """Every module executing ``node`` may import: ``from ..a import b`` is ``surfmod.a`` and,
    when ``b`` is a submodule, ``surfmod.a.b`` too."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    base = package[: len(package) - (node.level - 1)] if node.level else []
    module = ".".join([*base, node.module] if node.module else base)
    found = [module]
    for alias in node.names:
        if _module_path(f"{module}.{alias.name}", package_root):
            found.append(f"{module}.{alias.name}")
    return found


def _package_of(path: Path, package_root: Path) -> list[str]:
    return list(path.relative_to(package_root).with_suffix("").parts[:-1])


def module_level_graph(package_root: Path = PACKAGE.parent) -> dict[str, set[str]]:
    """surfmod module -> every module its import executes directly (module-level imports,
    plus the parent packages Python runs first)."""
    graph = {}
    for path in (package_root / "surfmod").rglob("*.py"):
        name = _module_name_under(path, package_root)
        tree = ast.parse(path.read_text(), filename=str(path))
        package = _package_of(path, package_root)
        edges = set()
        for node in _walk(tree, module_level_only=True):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for module in _resolved(node, package, package_root):
                    parts = module.split(".")
                    edges.update(".".join(parts[:k]) for k in range(1, len(parts) + 1))
        parts = name.split(".")
        edges.update(".".join(parts[:k]) for k in range(1, len(parts)))
        edges.discard(name)
        graph[name] = edges
    return graph


def _module_name_under(path: Path, package_root: Path) -> str:
    rel = path.relative_to(package_root).with_suffix("")
    return ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)


def heavy_modules(package_root: Path = PACKAGE.parent) -> set[str]:
    """surfmod modules whose import loads a LAZY library (directly or through another module)."""
    graph = module_level_graph(package_root)
    heavy = {name for name, edges in graph.items() if any(e.split(".")[0] in LAZY for e in edges)}
    while True:
        grown = heavy | {name for name, edges in graph.items() if edges & heavy}
        if grown == heavy:
            return heavy
        heavy = grown


def function_level_imports(path: Path, package_root: Path = PACKAGE.parent):
    """(node, modules) for every import statement inside a function body of ``path``."""
    tree = ast.parse(path.read_text(), filename=str(path))
    package = _package_of(path, package_root)
    found = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            if in_function and isinstance(child, (ast.Import, ast.ImportFrom)):
                found.append((child, _resolved(child, package, package_root)))
            visit(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))

    visit(tree, False)
    return found


def needless_lazy_imports(path: Path, package_root: Path = PACKAGE.parent, heavy: set[str] | None = None):
    """The function-level imports of ``path`` that have no reason to be lazy (see LAZY)."""
    heavy = heavy_modules(package_root) if heavy is None else heavy
    if path.relative_to(package_root).parts[:2] != ("surfmod", "occ"):
        occ = package_root / "surfmod" / "occ"
        heavy = heavy | {_module_name_under(p, package_root) for p in occ.rglob("*.py")}
    lines = path.read_text().splitlines()
    needless = []
    for node, modules in function_level_imports(path, package_root):
        commented = any(CYCLE_MARK.search(lines[i]) for i in (node.lineno - 1, node.lineno - 2) if i >= 0)
        if commented or any(m.split(".")[0] in LAZY or m in heavy for m in modules):
            continue
        needless.append(node)
    return needless


def _needless_by_file(package_root: Path = PACKAGE.parent) -> dict[str, list[str]]:
    heavy = heavy_modules(package_root)
    found = {}
    for path in sorted((package_root / "surfmod").rglob("*.py")):
        nodes = needless_lazy_imports(path, package_root, heavy)
        if nodes:
            found[path.relative_to(package_root).as_posix()] = [f"{n.lineno}: {ast.unparse(n)}" for n in nodes]
    return found


def test_function_level_imports_are_lazy_doors_only():
    found = _needless_by_file()
    offenders = [f"{f}:{line}" for f, lines in found.items() for line in lines]
    assert not offenders, (
        "imports inside functions that are neither LAZY libraries, modules loading them, nor marked "
        "'# cycle: a <-> b' (move them to the top of their module):\n" + "\n".join(offenders)
    )


def test_lazy_import_check_detects_a_needless_one(tmp_path):
    pkg = tmp_path / "surfmod"
    (pkg / "occ").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "occ" / "__init__.py").write_text("")
    (pkg / "occ" / "geom.py").write_text("from OCP.gp import gp_Pnt\n")
    (pkg / "light.py").write_text("import math\n")
    bad = pkg / "user.py"
    bad.write_text(
        "import numpy as np\n"
        "def f():\n"
        "    import scipy.sparse\n"
        "    from .occ.geom import gp_Pnt\n"
        "    from .light import math\n"
        "    # cycle: surfmod.user <-> surfmod.light\n"
        "    from . import light\n"
        "    import json\n"
        "    return np, scipy, gp_Pnt, math, light, json\n"
    )
    assert heavy_modules(tmp_path) == {"surfmod.occ.geom"}
    assert [ast.unparse(n) for n in needless_lazy_imports(bad, tmp_path)] == ["from .light import math", "import json"]


def test_no_import_cycle_at_module_level():
    # module-level imports form a DAG: the layers of DESIGN.md, readable from the top of each file
    graph = {name: {e for e in edges if e.startswith("surfmod.")} for name, edges in module_level_graph().items()}
    state, cycles = {}, []

    def visit(name, trail):
        state[name] = "open"
        for nxt in sorted(graph.get(name, ())):
            if state.get(nxt) == "open":
                cycles.append(" -> ".join([*trail[trail.index(nxt):], nxt]))
            elif nxt not in state:
                visit(nxt, [*trail, nxt])
        state[name] = "done"

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])
    # a package __init__ re-exporting its own modules is the one legitimate loop
    real = [c for c in cycles if not _package_reexport(c)]
    assert not real, "\n".join(real)


def _package_reexport(cycle: str) -> bool:
    names = cycle.split(" -> ")
    return all(a.startswith(b + ".") or b.startswith(a + ".") or a == b for a, b in zip(names, names[1:]))
