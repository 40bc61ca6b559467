"""Tables of the benchmarks: aligned text on a terminal, Markdown with ``--markdown``.

``python -m benchmarks NAME --markdown`` sets :data:`MARKDOWN` before the benchmark runs;
a benchmark prints through :class:`Table` and :func:`note`, never formats a table itself,
so the Markdown files under ``docs/benchmarks/`` are the benchmark's own output.

>>> t = Table(("net", 9), ("time", 8))
>>> t.header(); t.row("4x4", "0.0019s")
      net     time
------------------
      4x4  0.0019s
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile

MARKDOWN = False

#: a terminal colour code (OCCT colours its log lines)
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


class Table:
    """Columns of ``(title, width)`` or ``(title, width, "<")``; cells are strings the caller
    has formatted.

    Columns are right-aligned (numbers) unless marked ``"<"``; ``left_first`` marks the first.
    In Markdown the widths are ignored and the right-aligned columns get ``---:``.
    """

    def __init__(self, *columns: tuple, left_first: bool = False):
        self.columns = [(c[0], c[1]) for c in columns]
        self.left = [len(c) > 2 and c[2] == "<" or (i == 0 and left_first) for i, c in enumerate(columns)]

    def _text(self, cells) -> str:
        out = []
        for cell, (_, width), left in zip(cells, self.columns, self.left):
            out.append(f"{cell:<{width}}" if left else f"{cell:>{width}}")
        return " ".join(out)

    def header(self) -> None:
        titles = [title for title, _ in self.columns]
        if MARKDOWN:
            rule = ["---" if left else "---:" for left in self.left]
            print("\n| " + " | ".join(_escaped(t) for t in titles) + " |")
            print("|" + "|".join(rule) + "|")
        else:
            head = self._text(titles)
            print(head)
            print("-" * len(head))

    def row(self, *cells: str) -> None:
        if len(cells) != len(self.columns):
            raise ValueError(f"cells: {len(cells)} given for {len(self.columns)} columns")
        if MARKDOWN:
            print("| " + " | ".join(_escaped(c) for c in cells) + " |", flush=True)
        else:
            print(self._text(cells), flush=True)

    def rule(self) -> None:
        """A separating line before a total row (text only; Markdown has none)."""
        if not MARKDOWN:
            print("-" * len(self._text([t for t, _ in self.columns])))


def _escaped(cell) -> str:
    # a cell's own "|" (e.g. "max |dv|") would split it into two columns
    return str(cell).strip().replace("|", "\\|")


def note(text: str = "") -> None:
    """A line of explanation: as it is on a terminal, a paragraph of its own in Markdown."""
    if MARKDOWN:
        text = text.strip()
        print(f"\n{text}" if text else "")
    else:
        print(text)


def heading(text: str) -> None:
    """The title of the next table."""
    if MARKDOWN:
        print(f"\n**{text.strip()}**")
    else:
        print(text)


@contextlib.contextmanager
def captured_stdout():
    """Whatever C++ code (OCCT's log, OpenCAMLib's diagnostics) prints on file descriptor 1
    while the block runs, kept apart from the tables: yields a list that holds the
    printed lines, colour codes stripped and blank lines dropped, once the block ends.
    A benchmark says in a note what it needs of them, so a generated page holds only
    its tables and notes."""
    sys.stdout.flush()
    lines: list[str] = []
    saved = os.dup(1)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        try:
            yield lines
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)
            sink.seek(0)
            text = _ANSI.sub("", sink.read().decode("utf-8", "replace"))
            lines.extend(line.strip() for line in text.splitlines() if line.strip())
