"""``surfmod`` command line.  Each module in this package that defines
``register(subparsers)`` adds one subcommand (gallery, check, mesh, mass, …)."""

from __future__ import annotations

import argparse
import importlib
import re
import sys
import warnings
from pathlib import Path

from ..errors import InsideOutWarning, RoundTripWarning, SurfmodError
from ..version import installed_version


#: exit status of a command that wrote its output for part of the model only (faces OCCT
#: could not triangulate or intersect are named on the lines before)
EXIT_PARTIAL = 3

#: every spelling ``float()`` takes for a negative number: argparse's own pattern knows only
#: ``-12`` and ``-1.5``, so ``--origin -3.2e+04 1 2`` was read as an unknown option and the
#: flag as short of values
NEGATIVE_NUMBER = re.compile(r"^-(?:(?:\d[\d_]*(?:\.[\d_]*)?|\.\d[\d_]*)(?:[eE][+-]?\d[\d_]*)?|inf(?:inity)?|nan)$",
                             re.IGNORECASE)


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` that takes a negative number in any notation as a value,
    never as an option.  Subcommand parsers are of the same class (argparse makes them
    with ``type(parent)``), so the whole command line gets it at once.

    >>> p = Parser(prog="x"); _ = p.add_argument("--origin", nargs=3, type=float)
    >>> p.parse_args(["--origin", "-3.2e+04", "-.5", "-1E-3"]).origin
    [-32000.0, -0.5, -0.001]
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER


#: each subcommand and the module of this package that registers it; a command line that
#: names one loads only that module, so a command does not pay for the imports of the
#: others (``machine`` alone loads the CAM stack); ``tests/test_cli.py`` holds the table to
#: what the modules register
COMMANDS = {"analyze": "analyze", "check": "check", "conformance": "conformance", "convert": "exchange",
            "femesh": "femesh", "gallery": "gallery", "machine": "machine", "mass": "mass", "mesh": "mesh_stl",
            "section": "section", "toolpath": "toolpath"}


class _Version(argparse.Action):
    """``--version``: the installed version, looked up only when asked for (reading the
    metadata costs 0.1-0.2 s, which no other command line should pay)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="show program's version number and exit"):
        super().__init__(option_strings, dest, nargs=0, default=default, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"surfmod {installed_version()}")
        parser.exit()


def build_parser(argv=None) -> argparse.ArgumentParser:
    """The command line's parser: every subcommand, or only the one ``argv`` names."""
    parser = Parser(
        prog="surfmod",
        description="Surface-modeling toolbox on OpenCASCADE, cross-checked by NumPy.",
    )
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", required=True)
    named = next((a for a in (argv or []) if not a.startswith("-")), None)
    modules = [COMMANDS[named]] if named in COMMANDS else sorted(set(COMMANDS.values()))
    for name in modules:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)

    said = set()

    def one_line(message, category, *_args, **_kwargs):
        # a warning of surfmod's (an inside-out solid, a file that reads back changed) is
        # one line naming the command, like its errors, not Python's two-line form; said
        # once, though a command may meet the same solid in several passes
        text = " ".join(str(message).split())
        if text not in said:
            said.add(text)
            print(f"surfmod {args.command}: warning: {text}", file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", InsideOutWarning)
            warnings.simplefilter("always", RoundTripWarning)
            warnings.showwarning = one_line
            return int(args.run(args) or 0)
    except KeyboardInterrupt:
        # Ctrl-C: what was finished is written (a folder's CSV holds every finished file's
        # rows); one line and the shell's status for SIGINT, not a traceback
        print(f"surfmod {args.command}: interrupted", file=sys.stderr)
        return 130
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
