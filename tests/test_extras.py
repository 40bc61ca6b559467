"""pyproject.toml, the code and surfmod/extras.py agree on which libraries are hard
dependencies and which come with an extra; a missing extra is one clear error."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import surfmod as sm
from surfmod.extras import EXTRAS, require
from test_layering import EDGES

PYPROJECT = tomllib.loads((Path(__file__).resolve().parent.parent / "pyproject.toml").read_text())

#: distribution name -> the top-level modules it installs (where the two differ or are many)
MODULES_OF = {
    "cadquery-ocp": {"OCP"}, "cadquery-ocp-novtk": {"OCP"}, "matplotlib": {"matplotlib", "mpl_toolkits"},
    "dask[distributed]": {"dask", "distributed"},
}


def _modules(requirements) -> set[str]:
    out = set()
    for req in requirements:
        name = req.split(">")[0].split("<")[0].split("=")[0].split(";")[0].strip()
        if name.startswith("surfmod["):
            continue
        out |= MODULES_OF.get(name, {name.split("[")[0].replace("-", "_")})
    return out


HARD = _modules(PYPROJECT["project"]["dependencies"])
OPTIONAL = {extra: _modules(reqs) for extra, reqs in PYPROJECT["project"]["optional-dependencies"].items()}


def _third_party_imports() -> set[str]:
    names = {t.split(".")[0] for found in EDGES.values() for t, _, _ in found}
    return {n for n in names if n and n != "surfmod" and n not in sys.stdlib_module_names and n != "__future__"}


def test_every_library_the_code_imports_is_declared():
    declared = HARD | set().union(*(OPTIONAL[e] for e in EXTRAS))
    assert _third_party_imports() <= declared, _third_party_imports() - declared


def test_every_hard_dependency_is_used():
    used = _third_party_imports()
    # every hard dependency is imported by surfmod itself (OCP through build123d too)
    assert HARD - used == set(), HARD - used


def test_the_extras_table_is_pyproject_s():
    for extra, modules in EXTRAS.items():
        assert set(modules) <= OPTIONAL[extra], (extra, modules, OPTIONAL[extra])
        assert not set(modules) & HARD, f"{extra}: {set(modules) & HARD} is a hard dependency too"


def test_the_test_extra_pulls_every_extra_the_tests_need():
    test = PYPROJECT["project"]["optional-dependencies"]["test"]
    pulled = {e for req in test if req.startswith("surfmod[") for e in req[len("surfmod["):-1].split(",")}
    assert set(EXTRAS) <= pulled


def test_a_missing_extra_names_itself():
    with pytest.raises(sm.MissingExtraError, match=r'sm.fe_mesh needs the optional package .* pip install "surfmod\[fem\]"'):
        require("surfmod_no_such_package", "fem", "sm.fe_mesh")
    assert issubclass(sm.MissingExtraError, ImportError) and issubclass(sm.MissingExtraError, sm.SurfmodError)


_BLOCKED = """
import sys, importlib.abc
class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("gmsh", "meshio"):
            raise ImportError(name)
sys.meta_path.insert(0, Block())
import build123d as bd, surfmod as sm, tempfile, os
d = tempfile.mkdtemp()
try:
    sm.fe_mesh(bd.Box(1, 1, 1), 0.5, path=os.path.join(d, "box.msh"))
except sm.MissingExtraError as exc:
    print(exc)
print(os.listdir(d))
"""


def test_calls_without_their_extra_say_which_to_install():
    out = subprocess.run([sys.executable, "-c", _BLOCKED], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.strip().splitlines()
    assert lines[0] == 'sm.fe_mesh needs the optional package \'meshio\': pip install "surfmod[fem]"'
    assert lines[1] == "[]"  # no partial file


def test_every_upper_bound_names_its_reason():
    """No pin without a reason: each requirement with an upper bound sits under a comment
    (in its block of requirement and comment lines) naming the tested range or release,
    or the release that broke."""
    lines = (Path(__file__).resolve().parent.parent / "pyproject.toml").read_text().splitlines()
    requirement = re.compile(r'"[A-Za-z0-9_.\-\[\]]+[^"]*<[^"]*"')
    bounded = [i for i, line in enumerate(lines) if not line.lstrip().startswith("#") and requirement.search(line)]
    assert bounded, "pyproject.toml has no upper bound at all: this test reads it wrongly"
    for i in bounded:
        j, comments = i - 1, []
        while j >= 0 and lines[j].strip() and (lines[j].lstrip().startswith("#") or requirement.search(lines[j])):
            if lines[j].lstrip().startswith("#"):
                comments.append(lines[j])
            j -= 1
        assert re.search(r"tested|broke", " ".join(comments)), f"pyproject.toml line {i + 1}: an upper bound with no reason"
