"""Speed and quality benchmarks: ``python -m benchmarks`` runs them all and prints tables."""

import sys
from pathlib import Path

# the OCCT twins only tests and benchmarks use live in tests/twins (a package on the
# tests' own path): put that folder on this one too
_TESTS = str(Path(__file__).resolve().parent.parent / "tests")
if _TESTS not in sys.path:
    sys.path.append(_TESTS)
