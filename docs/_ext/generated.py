"""Sphinx extension: pages whose content comes from the code, not from a copy of it.

* ``api.rst``: the marker ``.. surfmod-api-reference`` becomes one section per group of
  :mod:`api_groups`, an ``autosummary`` table and an ``autoclass``/``autofunction`` entry
  for each public name, every one addressed as ``surfmod.NAME``.
* ``errors.md``: the marker ``<!-- surfmod-tolerances -->`` becomes a table of the named
  tolerances of :mod:`surfmod.tolerances`, each value read from the module and each meaning
  from its docstring.
* ``gallery.md``: the marker ``<!-- surfmod-gallery -->`` becomes one figure per PNG in
  ``docs/gallery/`` (made by ``docs/gallery_pictures.py``), captioned with its gallery
  entry's lecture entity and call.
* ``design.md``: the marker ``<!-- surfmod-package-map -->`` becomes a table of the
  subpackages and top-level modules of surfmod, each with the first sentence of its
  docstring, its modules and the surfmod packages it imports (read with :mod:`ast`,
  nothing imported, function-level imports included).
* ``design.md``: the marker ``<!-- surfmod-rank-table -->`` becomes the rank table of
  ``tests/test_layering.py`` (its ``RANKS`` list, and what each rank holds from the table
  in its docstring), so the page and the test cannot disagree.
* ``guide/stacks.md``: the marker ``<!-- surfmod-quirk-table -->`` becomes the table of
  OCCT quirks by release, read from the ``QUIRKS`` dict of ``tests/test_occt_quirks.py``
  (which asserts each one on the release it runs on).
* ``cli.md``: the marker ``<!-- surfmod-cli-reference -->`` becomes one section per
  subcommand of the ``surfmod`` parser: its usage line and a table of its arguments,
  taken from argparse (what ``surfmod CMD --help`` prints).

Module docstrings point to the page that explains their algorithm (``See :doc:`/guide/cam`
(section "Drop-cutter").``); Sphinx never renders them, so :func:`doc_references` checks
each such page and section exists and the build warns (an error under ``-W``) where not.
"""

from __future__ import annotations

import argparse
import ast
import inspect
import re
from pathlib import Path

import surfmod
from surfmod.transforms import Transformable

from . import api_groups

API_MARKER = ".. surfmod-api-reference"
CLI_MARKER = "<!-- surfmod-cli-reference -->"
TOL_MARKER = "<!-- surfmod-tolerances -->"
GALLERY_MARKER = "<!-- surfmod-gallery -->"
MAP_MARKER = "<!-- surfmod-package-map -->"
RANK_MARKER = "<!-- surfmod-rank-table -->"
QUIRK_MARKER = "<!-- surfmod-quirk-table -->"
LAYERING_TEST = Path(__file__).resolve().parents[2] / "tests" / "test_layering.py"
QUIRKS_TEST = Path(__file__).resolve().parents[2] / "tests" / "test_occt_quirks.py"
PACKAGE = Path(surfmod.__file__).resolve().parent
GALLERY = Path(__file__).resolve().parent.parent / "gallery"


def _grouped() -> list[tuple[str, str, list[str]]]:
    public = set(surfmod.__all__)
    groups, seen = [], set()
    for title, blurb, names in api_groups.GROUPS:
        kept = [n for n in names if n in public]
        seen.update(kept)
        if kept:
            groups.append((title, blurb, kept))
    rest = sorted(public - seen)
    if rest:
        groups.append(("Other public names", "Public names not yet placed in a section.", rest))
    return groups


def api_rst() -> str:
    lines = [".. currentmodule:: surfmod", ""]
    for title, blurb, names in _grouped():
        lines += [title, "-" * len(title), "", blurb, "", ".. autosummary::", ""]
        lines += [f"   {n}" for n in names]
        lines.append("")
        for n in names:
            obj = getattr(surfmod, n)
            if inspect.isclass(obj):
                lines += [f".. autoclass:: {n}", "   :members:"]
                if Transformable in obj.__bases__:  # its named transforms, written once in the mixin
                    lines.append("   :inherited-members: Immutable, ABC")
                lines.append("")
            else:
                lines += [f".. autofunction:: {n}", ""]
    return "\n".join(lines)


def _subcommands(parser: argparse.ArgumentParser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, helps.get(name, ""), sub


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def _sentence(text: str) -> str:
    text = _cell(text)
    return (text[:1].upper() + text[1:] + ("" if text.endswith(".") else ".")) if text else ""


def _argument_rows(sub: argparse.ArgumentParser):
    for a in sub._actions:
        if isinstance(a, argparse._HelpAction):
            continue
        if a.option_strings:
            flag = ", ".join(a.option_strings)
            if a.nargs != 0:
                if a.choices:
                    flag += " {" + ",".join(map(str, a.choices)) + "}"
                else:
                    meta = a.metavar if a.metavar is not None else a.dest.upper()
                    flag += " " + (" ".join(meta) if isinstance(meta, tuple) else meta)
        else:
            flag = a.metavar or a.dest
        required = "yes" if (a.required or not a.option_strings) else ""
        default = "" if a.default in (None, False, argparse.SUPPRESS) or not a.option_strings else repr(a.default)
        yield f"| `{_cell(flag)}` | {required} | {_cell(default)} | {_cell(a.help or '')} |"


def cli_md() -> str:
    from surfmod.cli import build_parser

    parser = build_parser()
    out = []
    for name, blurb, sub in sorted(_subcommands(parser)):
        usage = " ".join(sub.format_usage().split())
        out += [f"### `surfmod {name}`", "", _sentence(blurb), "", "```text", usage, "```", "",
                "| argument | required | default | meaning |", "|---|---|---|---|", *_argument_rows(sub), ""]
    return "\n".join(out)


def tolerances_md() -> str:
    from surfmod import tolerances

    meaning, name = {}, None
    for line in (tolerances.__doc__ or "").splitlines():
        if line.startswith("``") and line.rstrip().endswith("``"):
            name = line.strip().strip("`")
            meaning[name] = []
        elif name and line.strip():
            meaning[name].append(line.strip())
    rows = ["| name | value | meaning |", "|---|---|---|"]
    for name, words in meaning.items():
        value = getattr(tolerances, name)
        rows.append(f"| `{name}` | {value:g} | {_cell(' '.join(words))} |")
    return "\n".join(rows)


def gallery_md() -> str:
    from surfmod.gallery import entries

    known = {e.name: e for e in entries()}
    out = []
    for png in sorted(GALLERY.glob("*.png")):
        e = known.get(png.stem)
        caption = f"{e.entity}: `{e.call}`" if e else png.stem
        out += [f"```{{figure}} gallery/{png.name}", f":width: 320px", f":alt: {png.stem}", "", caption, "```", ""]
    return "\n".join(out) if out else "(no pictures yet: run `python docs/gallery_pictures.py`)"


def _first_sentence(path: Path) -> str:
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
    paragraph = " ".join(doc.split("\n\n")[0].split())
    end = paragraph.find(". ")
    return paragraph if end < 0 else paragraph[: end + 1]


def _imported_packages(path: Path, package: list[str]) -> set[str]:
    """The surfmod packages (or top-level modules) that ``path`` imports anywhere in it,
    function-level imports included, relative imports resolved."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)]
                names = [".".join(base + [node.module])] if node.module else [
                    ".".join(base + [a.name]) for a in node.names]
            else:
                names = [node.module or ""]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "surfmod" and len(parts) > 1:
                found.add(parts[1])
    return found


def package_map_md() -> str:
    rows = ["| package | what it holds | modules | imports from surfmod |", "|---|---|---|---|"]
    for init in sorted(PACKAGE.glob("*/__init__.py")):
        pkg = init.parent
        files = sorted(pkg.rglob("*.py"))
        modules = sorted(p.stem for p in pkg.glob("*.py") if p.stem != "__init__")
        uses = set()
        for f in files:
            uses |= _imported_packages(f, list(f.relative_to(PACKAGE.parent).parts[:-1]))
        uses.discard(pkg.name)
        rows.append(f"| `{pkg.name}/` | {_cell(_first_sentence(init))} | " + ", ".join(f"`{m}`" for m in modules)
                    + " | " + ", ".join(f"`{u}`" for u in sorted(uses)) + " |")
    top = sorted(p for p in PACKAGE.glob("*.py") if p.stem != "__init__")
    for f in top:
        uses = _imported_packages(f, ["surfmod"]) - {f.stem}
        rows.append(f"| `{f.name}` | {_cell(_first_sentence(f))} | | " + ", ".join(f"`{u}`" for u in sorted(uses)) + " |")
    return "\n".join(rows)


def _literal(path: Path, name: str):
    """The value of the module-level literal ``name`` assigned in the Python file ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return next(ast.literal_eval(node.value) for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))
                and any(isinstance(t, ast.Name) and t.id == name
                        for t in (node.targets if isinstance(node, ast.Assign) else [node.target])))


def rank_table_md(path: Path = LAYERING_TEST) -> str:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    ranks = _literal(path, "RANKS")
    holds = {}
    for line in (ast.get_docstring(tree) or "").splitlines():
        head, _, rest = line.partition(" ")
        if head.isdigit() and ":" in rest:
            holds[int(head)] = rest.split(":", 1)[1].strip()
    rows = ["| rank | packages / modules | holds |", "|---:|---|---|"]
    for rank, names in enumerate(ranks):
        rows.append(f"| {rank} | " + ", ".join(f"`{n}`" for n in names) + f" | {_cell(holds.get(rank, ''))} |")
    rows.append(f"| {len(ranks)} | `surfmod` (its `__init__`) | the public names, resolved lazily |")
    return "\n".join(rows)


def quirk_table_md(path: Path = QUIRKS_TEST) -> str:
    rows = ["| quirk | OCCT 7.9 | OCCT 8.0 | test |", "|---|---|---|---|"]
    for test, (what, *holds) in _literal(path, "QUIRKS").items():
        rows.append(f"| {_cell(what)} | " + " | ".join("holds" if h else "fixed" for h in holds) + f" | `{test}` |")
    return "\n".join(rows)


DOC_REFERENCE = re.compile(r':doc:`(/[\w/]+)`(?:\s+\(section\s+"([^"]+)"\))?')


def doc_references(package: Path = PACKAGE) -> list[str]:
    """Each ``:doc:`` reference in surfmod's sources whose page or section heading is missing."""
    docs, missing = GALLERY.parent, []
    for path in sorted(package.rglob("*.py")):
        for page, wrapped in DOC_REFERENCE.findall(path.read_text(encoding="utf-8")):
            section = " ".join(wrapped.split())
            target = docs / (page.lstrip("/") + ".md")
            headings = [line.lstrip("#").strip() for line in target.read_text(encoding="utf-8").splitlines()
                        if line.startswith("#")] if target.exists() else []
            if not target.exists() or (section and section not in headings):
                missing.append(f"{path.relative_to(package.parent)}: {page}" + (f' (section "{section}")' if section else ""))
    return missing


def _check_references(app):
    from sphinx.util import logging

    for reference in doc_references():
        logging.getLogger(__name__).warning(f"docstring points to no such page or section: {reference}")


def _source_read(app, docname, source):
    text = source[0]
    if API_MARKER in text:
        text = text.replace(API_MARKER, api_rst())
    if RANK_MARKER in text:
        text = text.replace(RANK_MARKER, rank_table_md())
    if MAP_MARKER in text:
        text = text.replace(MAP_MARKER, package_map_md())
    if GALLERY_MARKER in text:
        text = text.replace(GALLERY_MARKER, gallery_md())
    if TOL_MARKER in text:
        text = text.replace(TOL_MARKER, tolerances_md())
    if QUIRK_MARKER in text:
        text = text.replace(QUIRK_MARKER, quirk_table_md())
    if CLI_MARKER in text:
        text = text.replace(CLI_MARKER, cli_md())
    source[0] = text


def setup(app):
    app.connect("source-read", _source_read)
    app.connect("builder-inited", _check_references)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
