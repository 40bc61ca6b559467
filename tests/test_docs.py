"""The README and the documentation site agree with the code and with CI.

The site's generated parts (API reference, command-line reference, package map, the named
tolerances) come from ``docs/_ext/generated.py``; these tests run that generator without
Sphinx, so a broken page fails the default suite, not only the docs build.
"""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import surfmod

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"


def _generated():
    sys.path.insert(0, str(DOCS))
    try:
        return importlib.import_module("_ext.generated")
    finally:
        sys.path.remove(str(DOCS))


def test_api_reference_documents_every_public_name_once():
    rst = _generated().api_rst()
    documented = re.findall(r"^\.\. auto(?:class|function):: (\w+)$", rst, flags=re.M)
    assert sorted(documented) == sorted(surfmod.__all__)


def test_cli_reference_lists_every_subcommand_and_flag():
    from surfmod.cli import build_parser

    md = _generated().cli_md()
    sub = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, parser in sub.choices.items():
        assert f"### `surfmod {name}`" in md
        for action in parser._actions:
            for flag in action.option_strings:
                if flag not in ("-h", "--help"):
                    assert f"`{flag}" in md or f", {flag}" in md, (name, flag)


def test_package_map_names_every_subpackage():
    md = _generated().package_map_md()
    for init in (ROOT / "surfmod").glob("*/__init__.py"):
        assert f"| `{init.parent.name}/` |" in md


def test_named_tolerances_table_reads_the_module():
    from surfmod import tolerances

    md = _generated().tolerances_md()
    assert f"| `EXACT_RTOL` | {tolerances.EXACT_RTOL:g} |" in md


def test_readme_is_short_and_gives_the_commands_ci_runs():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert len(readme.splitlines()) <= 200
    for command in ('pip install -e ".[test,bench]" && surfmod gallery out/', "python -m pytest -q -n auto\n"):
        assert command in readme and command in ci
    assert "../shared" not in readme


def test_readme_links_point_at_files_of_the_repository():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", readme)
    assert targets
    missing = [t for t in targets if not t.startswith("http") and not (ROOT / t).exists()]
    assert not missing, missing


def test_benchmark_tables_print_markdown(capsys):
    from benchmarks import tables

    table = tables.Table(("net", 9), ("max |dv|", 8), ("note", 6, "<"))
    try:
        tables.MARKDOWN = True
        table.header()
        table.row("4x4", "1e-16", "ok")
    finally:
        tables.MARKDOWN = False
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines == ["| net | max \\|dv\\| | note |", "|---:|---:|---|", "| 4x4 | 1e-16 | ok |"]


def test_design_page_rank_table_is_the_layering_tests():
    import test_layering

    md = _generated().rank_table_md()
    for rank, names in enumerate(test_layering.RANKS):
        assert f"| {rank} | " + ", ".join(f"`{n}`" for n in names) + " |" in md


def _pages():
    return [ROOT / "README.md", *sorted(DOCS.glob("*.md")), *sorted((DOCS / "guide").glob("*.md"))]


def test_pages_name_only_modules_and_functions_that_exist():
    # a module moved or renamed must take its mentions in the manual with it
    missing = []
    for page in _pages():
        text = page.read_text(encoding="utf-8")
        for path in set(re.findall(r"surfmod/[a-z_/]+\.py", text)):
            if not (ROOT / path).exists():
                missing.append(f"{page.name}: {path}")
        for dotted in set(re.findall(r"\bsurfmod(?:\.[A-Za-z_]+)+", text)):
            parts = dotted.split(".")
            for cut in range(len(parts), 0, -1):
                base = ROOT.joinpath(*parts[:cut])
                source = base.with_suffix(".py") if base.with_suffix(".py").exists() else base / "__init__.py"
                if source.exists():
                    rest = parts[cut:]
                    if rest and not re.search(rf"^\s*(?:def|class) {rest[0]}\b|^{rest[0]}\s*[:=]",
                                              source.read_text(encoding="utf-8"), flags=re.M):
                        missing.append(f"{page.name}: {dotted}")
                    break
            else:
                missing.append(f"{page.name}: {dotted}")
    assert not missing, missing


#: a line OCCT's message system prints (``*** ERR StepReaderData : …``, ``**** WARN …``)
_OCCT_LOG = re.compile(r"^\s*\*{3,}\s*(?:ERR|FAIL|WARN|INFO|TRACE)\b")


def stray_lines(text: str) -> list[str]:
    """The lines of a Markdown page that no page means to hold: a terminal's colour codes,
    an OCCT log line, or a line inside a table that is not a row of it (a program's output
    that leaked into a generated table)."""
    stray, in_table = [], False
    for number, line in enumerate(text.splitlines(), 1):
        is_row = line.lstrip().startswith("|")
        if "\x1b" in line or _OCCT_LOG.match(line) or (in_table and line.strip() and not is_row):
            stray.append(f"line {number}: {line!r}")
        in_table = is_row or (in_table and bool(line.strip()))
    return stray


def test_stray_lines_are_found():
    table = "| a | b |\n|---|---:|\n| x | 1 |\n"
    assert stray_lines(table + "\nA note.\n") == []
    log = "\x1b[32;1m*** ERR StepReaderData : Unresolved Reference : Fails Count : 16 ***\x1b[0m"
    assert len(stray_lines(table + log + "\n| y | 2 |\n")) == 1
    assert len(stray_lines(table + "\n*** ERR StepReaderData : Unresolved Reference ***\n")) == 1
    assert len(stray_lines("| a |\n|---|\nsome output\n| b |\n")) == 1


def test_pages_hold_no_stray_line():
    # a generated page (docs/benchmarks/) holds only the tables and notes it claims
    pages = [*_pages(), *sorted((DOCS / "benchmarks").glob("*.md"))]
    found = {page.name: lines for page in pages if (lines := stray_lines(page.read_text(encoding="utf-8")))}
    assert not found, found
