"""Run every benchmark module (``bench_*.py``) in this folder and print their tables.

``python -m benchmarks``            all benchmarks
``python -m benchmarks eval mesh``  only the named ones
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
from pathlib import Path


def main(argv: list[str]) -> int:
    here = Path(__file__).resolve().parent
    names = sorted(m.name for m in pkgutil.iter_modules([str(here)]) if m.name.startswith("bench_"))
    # benchmark names come before the first option (``real --only mesh`` is not ``mesh``)
    chosen = argv[: next((i for i, a in enumerate(argv) if a.startswith("--")), len(argv))]
    wanted = [n for n in names if not chosen or n.removeprefix("bench_") in chosen]
    for name in wanted:
        module = importlib.import_module(f"benchmarks.{name}")
        print(f"\n=== {name} ===")
        module.main()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
