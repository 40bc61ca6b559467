"""Every script in examples/ runs and writes readable STEP/STL files into step_samples/.

Scripts run in-process (build123d is imported once) from a copy of the folder, so the
repository's step_samples/ is left alone.
"""

from __future__ import annotations

import runpy
import shutil
from pathlib import Path

import pytest

import surfmod as sm
from surfmod.cli.check import check_file

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SCRIPTS = sorted(p.name for p in EXAMPLES.glob("*.py"))


@pytest.mark.parametrize("script", SCRIPTS)
def test_example_runs_and_writes_samples(script, tmp_path, capsys):
    (tmp_path / "examples").mkdir()
    (tmp_path / "step_samples").mkdir()
    copy = tmp_path / "examples" / script
    shutil.copy(EXAMPLES / script, copy)
    runpy.run_path(str(copy), run_name="__main__")
    written = sorted((tmp_path / "step_samples").iterdir())
    assert written, f"{script} wrote nothing into step_samples/"
    for path in written:
        assert path.stat().st_size > 0
        if path.suffix == ".step":
            assert sm.import_step(path).faces() or sm.import_step(path).edges()
            # what `surfmod check` does: every face read back into NumPy agrees with OCCT
            failed = [row for row in check_file(path, samples=24) if not row[4]]
            assert not failed, failed
