"""DESIGN.md rule 1: only surfmod/occ/ imports OCP; import surfmod stays light."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "surfmod"


def _imported_modules(path: Path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, node.lineno
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module, node.lineno


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
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from OCP.gp import gp_Pnt\n")
    assert [m for m, _ in _imported_modules(bad)] == ["OCP.gp"]


def test_nets_and_eval_are_pure_numpy():
    for sub in ("nets", "eval"):
        for path in (PACKAGE / sub).rglob("*.py"):
            for module, line in _imported_modules(path):
                assert not module.startswith(("build123d", "cadquery", "OCP")), f"{path}:{line} imports {module}"


def test_import_surfmod_is_light():
    code = (
        "import sys, time; t = time.perf_counter(); import surfmod; dt = time.perf_counter() - t; "
        "print(dt, 'OCP' in sys.modules, 'build123d' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out[1] == "False" and out[2] == "False", "import surfmod must not load OCP/build123d"
    assert float(out[0]) < 0.5
