"""The command line: gallery and check (driven in-process and as a real console script)."""

from __future__ import annotations

import importlib.metadata
import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import surfmod as sm
from surfmod.cli import main


def test_help_lists_the_subcommands(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for name in ("gallery", "check"):
        assert name in out


def _pyproject_version() -> str:
    text = (Path(__file__).resolve().parent.parent / "pyproject.toml").read_text()
    # (tomllib is Python 3.11+; the project supports 3.10)
    return re.search(r'^version = "([^"]+)"$', text, flags=re.MULTILINE).group(1)


def test_version_comes_from_the_installed_metadata(capsys):
    # one source (pyproject.toml) -> the metadata pip wrote -> sm.__version__ and --version
    version = importlib.metadata.version("surfmod")
    assert version == _pyproject_version() == sm.__version__
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"surfmod {version}\n"


def test_version_of_an_uninstalled_tree_says_so():
    from surfmod.version import NOT_INSTALLED, installed_version

    assert installed_version("surfmod-no-such-distribution") == NOT_INSTALLED
    assert installed_version("numpy") == np.__version__


def test_check_reports_every_face(tmp_path, capsys):
    import build123d as bd

    rng = np.random.default_rng(0)
    sm.export_step(sm.BSplineSurface(rng.uniform(-1, 1, (5, 5, 3)), (3, 3)), tmp_path / "a.step")
    bd.export_step(bd.Box(1, 2, 3), str(tmp_path / "box.step"))
    code = main(["check", str(tmp_path), "--no-progress", "--jobs", "2", "--samples", "8"])  # worker processes
    out = capsys.readouterr().out
    assert code == 0, out
    assert "Geom_BSplineSurface" in out and "Geom_Plane" in out
    assert "7 of 7 faces passed" in out


def test_check_exits_nonzero_on_bad_files(tmp_path, capsys):
    (tmp_path / "bad.step").write_text("ISO-10303-21;\nnonsense\n")
    code = main(["check", str(tmp_path / "bad.step"), "--no-progress"])
    assert code == 1
    assert "NO" in capsys.readouterr().out
    assert main(["check", str(tmp_path / "missing.step"), "--no-progress"]) == 1


@pytest.mark.skipif(importlib.util.find_spec("cadquery") is None,
                    reason="cadquery is the 'cadquery' extra (OCCT 7.9); this venv is on the other stack")
def test_cadquery_step_files_read_back(tmp_path, capsys):
    import cadquery as cq

    part = cq.Workplane().box(4, 3, 2).edges("|Z").fillet(0.5).faces(">Z").hole(1.0)
    cq.exporters.export(part, str(tmp_path / "cq.step"))
    code = main(["check", str(tmp_path / "cq.step"), "--no-progress", "--samples", "8"])
    out = capsys.readouterr().out
    assert code == 0, out


def _console_script():
    beside = Path(sys.executable).parent / "surfmod"
    return str(beside) if beside.exists() else shutil.which("surfmod")


@pytest.mark.skipif(_console_script() is None, reason="surfmod console script not installed")
def test_console_script_runs_the_gallery(tmp_path):
    out = subprocess.run(
        [_console_script(), "gallery", str(tmp_path), "--only", "bezier", "hermite", "--no-progress"],
        capture_output=True, text=True,
    )
    assert out.returncode == 0, out.stderr
    assert "2 of 2 entities passed" in out.stdout
    version = subprocess.run([_console_script(), "--version"], capture_output=True, text=True, check=True)
    assert version.stdout.strip() == f"surfmod {sm.__version__}"
    for name in ("bezier", "hermite"):
        assert (tmp_path / f"{name}.step").stat().st_size > 0
        assert (tmp_path / f"{name}.stl").stat().st_size > 0
        back = sm.import_step(tmp_path / f"{name}.step")
        assert sm.crosscheck(back.faces()[0]).passed


def test_gallery_unknown_entity(capsys):
    assert main(["gallery", "/tmp/unused", "--only", "nope"]) == 1
    assert "only: unknown entities nope" in capsys.readouterr().err


def test_mesh_command_writes_a_watertight_stl(tmp_path, capsys):
    import build123d as bd
    import trimesh

    part = bd.Box(20, 20, 10) - bd.Cylinder(5, 30)
    bd.export_step(part, str(tmp_path / "part.step"))
    assert main(["mesh", str(tmp_path / "part.step"), "--tolerance", "0.02"]) == 0
    out = capsys.readouterr().out
    assert "watertight True" in out
    stl = trimesh.load(tmp_path / "part.stl")
    assert stl.is_watertight and abs(stl.volume - part.volume) < 0.01 * part.volume


def test_mesh_of_a_small_part_loads_neither_numba_nor_joblib(tmp_path):
    """A fresh ``surfmod mesh`` of a 96-face part (one B-spline face: 25 estimate samples,
    67k measure samples) runs its estimate and measure in NumPy: loading numba and the
    kernels was half of the command's time (issue 34's start-up row), and joblib serves
    folder runs only."""
    part = Path(__file__).resolve().parent / "data" / "step" / "trimesh_featuretype.STEP"
    script = ("import sys\nfrom surfmod.cli import main\n"
              "assert main(['mesh', sys.argv[1], '--out', sys.argv[2], '--no-progress']) == 0\n"
              "print([m for m in ('numba', 'joblib') if m in sys.modules])\n")
    done = subprocess.run([sys.executable, "-c", script, str(part), str(tmp_path / "part.stl")], capture_output=True,
                          text=True, check=True)
    assert "watertight True" in done.stdout and done.stdout.splitlines()[-1] == "[]", done.stdout


def test_gallery_table_keeps_long_names_whole():
    from surfmod.gallery.runner import GalleryRow, format_table

    long = "Catmull–Clark limit of a pentagonal prism (mixed polygons)"
    rows = [GalleryRow("a", long, "Solid", "per-face", 7.1e-15, True), GalleryRow("b", "sphere", "Geom_SphericalSurface", "parametric", 0.0, False)]
    lines = format_table(rows).splitlines()
    assert long in lines[2] and lines[2].endswith("yes")
    assert lines[3].endswith("NO")
    assert lines[2].index("Solid") == lines[3].index("Geom_SphericalSurface") == lines[0].index("OCCT construct")


# -- negative numbers in any notation are values, on every command -------------------------------
NEGATIVES = ["-3.2e+04", "-1E-3", "-.5", "-5.", "-1_000.25", "-7", "-2.5E+0"]


def _float_flags():
    """Every float-typed flag of every subcommand, read from the parser itself."""
    import argparse

    from surfmod.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name, parser in sub.choices.items():
        for action in parser._actions:
            if action.type is float and action.option_strings:
                yield name, action


@pytest.mark.parametrize("text", NEGATIVES)
def test_every_float_flag_takes_a_negative_number(text):
    """Parse-level, every command: the flag gets ``float(text)`` (argparse's own pattern
    knew only -12 and -1.5 and took the rest for options)."""
    import argparse

    from surfmod.cli import build_parser

    flags = list(_float_flags())
    assert {"section", "machine", "mesh", "toolpath", "femesh", "mass"} <= {n for n, _ in flags}
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name, action in flags:
        parser = sub.choices[name]
        # the flag alone: the other required flags let go, a dummy for each positional
        for a in parser._actions:
            a.required = False
        for g in parser._mutually_exclusive_groups:
            g.required = False
        positionals = ["x"] * sum(1 for a in parser._actions if not a.option_strings and a.nargs != "?")
        count = action.nargs if isinstance(action.nargs, int) else 1
        values = parser.parse_args([*positionals, action.option_strings[0], *[text] * count])
        got = getattr(values, action.dest)
        assert (got if isinstance(got, list) else [got]) == [float(text)] * count, (name, action.dest)


def test_section_origin_in_exponent_notation(tmp_path, capsys):
    """A part far on the negative side, cut through ``--origin -3.2e+04 …``: the square of
    side 2 (perimeter 8) in the DXF."""
    import build123d as bd
    from test_corpus_readback import dxf_length

    path, out = tmp_path / "far.step", tmp_path / "far.dxf"
    sm.export_step(bd.Pos(-32000, -0.1, 1e-3) * bd.Box(2, 2, 2), path)
    code = main(["section", str(path), "--origin", "-3.2e+04", "-1E-1", "-.5", "--normal", "-1e0", "0", "-0.",
                 "--out", str(out), "--no-progress"])
    assert code == 0, capsys.readouterr().err
    assert dxf_length(out) == pytest.approx(8.0, rel=1e-12)


def test_machine_stock_in_exponent_notation(tmp_path, capsys):
    """``--stock`` in exponent notation reaches the stock check (a box beside the part is
    refused naming ``stock``), not argparse's "expected 6 arguments"."""
    import build123d as bd

    path, out = tmp_path / "part.step", tmp_path / "job.ngc"
    sm.export_step(bd.Box(10, 10, 5), path)
    code = main(["machine", str(path), "--out", str(out), "--stock", "-4e+01", "-4E+01", "-3e1", "-3.5e+01", "-3.5e1",
                 "-2.5e+01", "--rough", "flat:3", "--finish", "ball:1", "--scallop", "1e-2", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 1 and err.startswith("surfmod machine: error: stock:") and err.count("\n") == 1, err
    assert "[-40.0, -40.0, -30.0, -35.0, -35.0, -25.0]" in err
    assert not out.exists()


def test_mesh_negative_tolerance_is_named(tmp_path, capsys):
    import build123d as bd

    path = tmp_path / "part.step"
    sm.export_step(bd.Box(1, 1, 1), path)
    assert main(["mesh", str(path), "--tolerance", "-1e-3", "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("surfmod mesh: error: tolerance") and err.count("\n") == 1, err
    assert not (tmp_path / "part.stl").exists()


def test_section_on_a_planar_face_draws_its_outline(tmp_path, capsys):
    """``--origin`` on the top face of a box with a hole: exit 0, the DXF is the face's
    outline (square 8 + circle pi), and the command names the face."""
    import build123d as bd
    from test_corpus_readback import dxf_length

    path, out = tmp_path / "part.step", tmp_path / "top.dxf"
    sm.export_step(bd.Box(2, 2, 2) - bd.Cylinder(0.5, 3), path)
    assert main(["section", str(path), "--origin", "0", "0", "1", "--normal", "0", "0", "1", "--out", str(out),
                 "--no-progress"]) == 0
    assert "lies on planar face(s) [2]: their outline included" in capsys.readouterr().out
    assert dxf_length(out) == pytest.approx(8 + np.pi, rel=1e-12)


# -- a command loads only its own module ---------------------------------------------------------
def test_command_table_is_what_the_modules_register():
    """``COMMANDS`` names every module of ``surfmod.cli`` that registers a subcommand, with
    the subcommand it registers, so a command line that names one loads only that module."""
    import argparse
    import importlib
    import pkgutil

    import surfmod.cli as cli

    registered = {}
    for info in pkgutil.iter_modules(cli.__path__):
        module = importlib.import_module(f"surfmod.cli.{info.name}")
        if hasattr(module, "register"):
            sub = argparse.ArgumentParser().add_subparsers()
            module.register(sub)
            registered.update({name: info.name for name in sub.choices})
    assert cli.COMMANDS == registered


def test_a_command_loads_no_other_command():
    """``surfmod mass --help`` in a fresh process imports no CAM module and no other command."""
    code = ("import sys, contextlib, io\nfrom surfmod.cli import main\n"
            "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
            "    main(['mass', '--help'])\n"
            "print(sorted(m for m in sys.modules if m.startswith(('surfmod.cli.', 'surfmod.cam'))))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = eval(done.stdout.strip().splitlines()[-1])
    assert "surfmod.cli.mass" in loaded
    assert not [m for m in loaded if m.startswith("surfmod.cam") or m in ("surfmod.cli.machine", "surfmod.cli.mesh_stl")]
