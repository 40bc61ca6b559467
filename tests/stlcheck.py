"""Reading STL files back with a real STL client: Debian's ``admesh`` (shared by the STL
tests)."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

# admesh's counters of problems found or repaired: all zero for an STL that needs no repair
ADMESH_REPAIRS = (
    "Facets with 1 disconnected edge",
    "Total disconnected facets",
    "Degenerate facets",
    "Edges fixed",
    "Facets removed",
    "Facets added",
    "Facets reversed",
    "Backwards edges",
    "Normals fixed",
)


def admesh_stats(path):
    out = subprocess.run(["admesh", str(path)], capture_output=True, timeout=60).stdout
    out = out.decode("utf-8", errors="replace")  # admesh echoes the raw 80-byte header
    stats = {}
    for key in ("Number of facets", "Number of parts", *ADMESH_REPAIRS):
        match = re.search(re.escape(key) + r"\s*:\s*(\d+)", out)
        assert match, f"admesh output lacks {key!r}:\n{out}"
        stats[key] = int(match.group(1))
    vol = re.search(r"Volume\s*:\s*([-0-9.eE+]+)", out)
    stats["Volume"] = float(vol.group(1))
    return stats



#: skip marker for tests that need admesh
needs_admesh = pytest.mark.skipif(shutil.which("admesh") is None, reason="admesh not installed (apt-get install admesh)")
