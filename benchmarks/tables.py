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

MARKDOWN = False


class Table:
    """Columns of ``(title, width)``; cells are strings the caller has formatted.

    The first column is left-aligned when ``left_first`` is true; the others are right-aligned
    (numbers).  In Markdown the widths are ignored and the number columns get ``---:``.
    """

    def __init__(self, *columns: tuple[str, int], left_first: bool = False):
        self.columns = columns
        self.left_first = left_first

    def _text(self, cells) -> str:
        out = []
        for i, (cell, (_, width)) in enumerate(zip(cells, self.columns)):
            out.append(f"{cell:<{width}}" if i == 0 and self.left_first else f"{cell:>{width}}")
        return " ".join(out)

    def header(self) -> None:
        titles = [title for title, _ in self.columns]
        if MARKDOWN:
            rule = ["---" if i == 0 else "---:" for i in range(len(titles))]
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
