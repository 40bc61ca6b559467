"""Every script in examples/ runs, writes readable STEP/STL files into step_samples/ and
keeps the promises it prints: every cross-check it shows passes, every measured figure it
sets beside a tolerance or a closed form agrees with it.

Scripts run in-process (build123d is imported once) from a copy of the folder, so the
repository's step_samples/ is left alone.
"""

from __future__ import annotations

import re
import runpy
import shutil
from pathlib import Path

import numpy as np

import pytest

import surfmod as sm
from surfmod.cli.check import check_file

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SCRIPTS = sorted(p.name for p in EXAMPLES.glob("*.py"))

NUM = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
VEC = r"\[([^\]]*)\]"


def _close(a, b, rel):
    a, b = float(a), float(b)
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def _vec(text):
    return np.array(text.replace(",", " ").split(), dtype=float)


# What any example may print, and what must then hold.
GENERIC = [
    (r"CrossCheck\((?:parametric|geometric), \d+ samples, max deviation \S+, (\w+)\)", lambda ok: ok == "passed"),
    (rf"max deviation {NUM} <= tolerance {NUM}", lambda a, b: float(a) <= float(b)),
    (rf"^tolerance {NUM}: .*measured max deviation {NUM}", lambda t, d: float(d) <= float(t)),
    (rf"max \|z - f\| = {NUM} \(tolerance {NUM}\)", lambda a, b: float(a) <= float(b)),
    (r"watertight:? (\w+)", lambda w: w == "True"),
    (r"valid (\w+)", lambda w: w == "True"),
    (r"complete=(\w+)", lambda w: w == "True"),
    (rf"max gouge {NUM} \(tolerance {NUM}\)", lambda g, t: float(g) <= float(t)),
    (rf"\|A-B\| {NUM}", lambda d: float(d) < 1e-12),
    (rf"max deviation from gp_G?Trsf: {NUM}", lambda d: float(d) < 1e-12),
    (rf"max \|F\| on (?:NURBS )?points(?: =)? {NUM}", lambda f: float(f) < 1e-9),
    (rf"area {NUM} vs [^=]*= {NUM}$", lambda a, b: _close(a, b, 1e-8)),
    (rf"volume {NUM} vs {NUM}$", lambda a, b: _close(a, b, 1e-8)),
]

# Figures particular to one script.
PROMISES = {
    "mass_properties.py": [
        (rf"BRepGProp eps=1e-9 volume error vs closed form {NUM}", lambda e: float(e) < 1e-9),
        (rf"NumPy quadrature volume error vs closed form {NUM}", lambda e: float(e) < 1e-13),
        (rf"STEP part: volume {NUM} \(BRepGProp {NUM}\)", lambda a, b: _close(a, b, 1e-9)),
    ],
    "trim.py": [(rf"rel\. diff {NUM}", lambda d: float(d) < 1e-9)],
    "plane_three_points.py": [(rf"S\(0\.5, 0\.5\) = {VEC} = .* = {VEC}", lambda a, b: np.allclose(_vec(a), _vec(b)))],
    "uniform_cubic.py": [(rf"matrix form {VEC} surfmod {VEC}", lambda a, b: np.allclose(_vec(a), _vec(b), rtol=1e-8))],
    "interpolate_approximate.py": [
        (rf"interpolate .*: ours {NUM}, OCCT", lambda d: float(d) < 1e-12),
        (rf"control points: ours {NUM}, OCCT {NUM} \(tolerance {NUM}\)", lambda a, _b, t: float(a) <= float(t)),
    ],
    "intersect.py": [
        (rf"\|dL\| to OCCT {NUM}", lambda d: float(d) < 1e-5),
        (rf"line hits \(u, v, t\): \[{VEC}\] OCCT IntCS: \[{VEC}\]", lambda a, b: np.allclose(_vec(a), _vec(b))),
    ],
    "section.py": [(rf"sphere section radius {NUM} expected {NUM}", lambda r, e: _close(r, e, 1e-12))],
    "read_back_step.py": [(rf"faces read back, max deviation {NUM}", lambda d: float(d) < 1e-12)],
    "subdivision_cube.py": [(rf"gap between patches\s+{NUM}", lambda d: float(d) < 1e-12)],
    "ruled_surface.py": [
        (rf"vs GeomFill::Surface at v=0\.5: {NUM}", lambda d: float(d) < 1e-12),
        (rf"shell area {NUM} = {NUM} \+ {NUM}", lambda a, b, c: _close(a, float(b) + float(c), 1e-6)),
    ],
    "project_shadow.py": [(rf"max \|du\| {NUM}", lambda d: float(d) < 1e-12)],
    "interference.py": [(r"interference report: (\w+)", None)],
    "fe_mesh.py": [(rf"curved \(order 2\) surface area {NUM} vs exact {NUM}", lambda a, b: _close(a, b, 1e-4))],
}


def _kept_promises(script: str, output: str) -> list[str]:
    """Each printed figure that breaks its promise, as a readable line."""
    broken = []
    for pattern, holds in GENERIC + PROMISES.get(script, []):
        matches = list(re.finditer(pattern, output, flags=re.MULTILINE))
        if pattern in dict(PROMISES.get(script, [])) and not matches:
            broken.append(f"{script} no longer prints {pattern!r}")
        for m in matches:
            if holds is not None and not holds(*m.groups()):
                broken.append(f"{script}: {m.group(0)!r}")
    if script == "interference.py":
        kinds = re.findall(r"interference report: (\w+)", output)
        if kinds[:3] != ["CLEARANCE", "CONTACT", "INTERFERENCE"]:
            broken.append(f"interference.py: shaft reports {kinds[:3]}, expected clearance, contact, interference")
    return broken


def test_promise_checker_can_fail():
    out = "CrossCheck(parametric, 64 samples, max deviation 1e-3, FAILED)\nsphere area 1.0 vs 4 pi R^2 = 1.1\n"
    assert len(_kept_promises("quadrics.py", out)) == 2
    assert _kept_promises("trim.py", "")[0].startswith("trim.py no longer prints")


@pytest.mark.parametrize("script", SCRIPTS)
def test_example_runs_and_writes_samples(script, tmp_path, capsys):
    (tmp_path / "examples").mkdir()
    (tmp_path / "step_samples").mkdir()
    copy = tmp_path / "examples" / script
    shutil.copy(EXAMPLES / script, copy)
    runpy.run_path(str(copy), run_name="__main__")
    broken = _kept_promises(script, capsys.readouterr().out)
    assert not broken, "\n".join(broken)
    written = sorted((tmp_path / "step_samples").iterdir())
    assert written, f"{script} wrote nothing into step_samples/"
    for path in written:
        assert path.stat().st_size > 0
        if path.suffix == ".step":
            assert sm.import_step(path).faces() or sm.import_step(path).edges()
            # what `surfmod check` does: every face read back into NumPy agrees with OCCT
            failed = [row for row in check_file(path, samples=24) if not row[4]]
            assert not failed, failed
