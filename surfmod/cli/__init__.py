"""``surfmod`` command line.  Each module in this package that defines
``register(subparsers)`` adds one subcommand (gallery, check, mesh, mass, …)."""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from pathlib import Path

from ..errors import SurfmodError
from ..version import installed_version


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="surfmod",
        description="Surface-modeling toolbox on OpenCASCADE, cross-checked by NumPy.",
    )
    parser.add_argument("--version", action="version", version=f"surfmod {installed_version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(module, "register"):
            module.register(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.run(args) or 0)
    except SurfmodError as exc:
        # one line, no traceback: bad input is the user's to fix, not a crash; a message
        # about a part that does not say which file it read gets the file appended
        message = " ".join(str(exc).split())
        inputs = getattr(args, "path", None) or getattr(args, "step", None) or []
        inputs = [inputs] if isinstance(inputs, str) else list(inputs)
        if len(inputs) == 1 and Path(inputs[0]).name not in message:
            message += f" (in {inputs[0]})"
        print(f"surfmod {args.command}: error: {message}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
