"""The program header's verification note fits LinuxCNC's line: rs274ngc refuses a line
longer than 255 characters ("Command too long"), which the note of a job whose findings
include the holder and shank (503 characters on asitus_topEdgeFillets_4) was."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from stock_sim import RS274, run_rs274

from surfmod.cam.post import LINE_LENGTH, _header

FINDINGS = [
    "gouge, roughing [tool 1]: nothing inside the tool, limit 0.0501 mm, ok",
    "gouge, finishing [tool 2]: nothing inside the tool, limit 0.0031 mm, ok",
    "rapids: nothing inside the tool, limit 0 mm, ok",
    "holder and shank, roughing [tool 1]: nothing inside the tool, limit 0.00584 mm, ok",
    "holder and shank, finishing [tool 2]: nothing inside the tool, limit 0.00584 mm, ok",
    "residual after finishing [tool 2, normal to the reachable surface]: max 0.0261 mm at [77.61, 31.25, -38.81], "
    "limit 0.0335 mm, ok",
    "a finding of its own longer than a line: " + "word " * 80,
]


def _lines():
    job = SimpleNamespace(stock=(np.zeros(3), np.array([10.0, 10.0, 5.0])))
    return _header(job, "surfmod job: 2 operations, LinuxCNC", "verified: " + "; ".join(FINDINGS))


def test_every_header_line_fits_and_every_word_is_kept():
    lines = _lines()
    assert max(map(len, lines)) <= LINE_LENGTH
    stock = next(k for k, line in enumerate(lines) if line.startswith("(stock"))
    kept = " ".join(line[1:-1] for line in lines[2:stock]).split()
    assert kept == ("verified: " + "; ".join(FINDINGS)).replace(";", "").split()
    assert len(lines[2:stock]) > len(FINDINGS)  # a line per finding, the longest one wrapped


@pytest.mark.skipif(RS274 is None, reason="rs274 (linuxcnc-uspace) is not installed")
def test_linuxcnc_reads_the_header(tmp_path):
    ngc = tmp_path / "header.ngc"
    ngc.write_text("\n".join(_lines() + ["M2", "%", ""]))
    assert "PROGRAM_END" in run_rs274(ngc)
