"""The uses subcommands driven through ``surfmod.cli.main``."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm
from surfmod.cli import main

import build123d as bd


@pytest.fixture(scope="module")
def part(tmp_path_factory):
    """A 20 x 20 x 5 block with filleted top edges, as a STEP file."""
    box = bd.Box(20, 20, 5)
    solid = bd.fillet(box.edges().group_by(bd.Axis.Z)[-1], radius=2)
    path = tmp_path_factory.mktemp("cli") / "part.step"
    sm.export_step(solid, path)
    return path, solid


def test_mass(part, capsys):
    path, solid = part
    assert main(["mass", str(path), "--density", "2", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "volume" in out and "BRepGProp" in out
    r = sm.mass_properties(str(path))
    assert r.volume == pytest.approx(solid.volume, rel=1e-9)
    # 4 edge fillets remove (4 - pi) r^2 per unit length, corners a little less each
    assert 2000 - 4 * 20 * (4 - math.pi) < r.volume < 2000 - 4 * 16 * (4 - math.pi)


def test_section(part, tmp_path, capsys):
    import ezdxf

    path, _ = part
    out = tmp_path / "s.dxf"
    assert main(["section", str(path), "--origin", "0", "0", "0", "--normal", "1", "0", "0",
                 "--out", str(out), "--png", str(tmp_path / "s.png"), "--no-progress"]) == 0
    ents = ezdxf.readfile(out).modelspace()
    assert len(ents) >= 1 and {e.dxftype() for e in ents} <= {"LINE", "ARC", "CIRCLE", "SPLINE"}
    assert (tmp_path / "s.png").exists() and "1 closed" in capsys.readouterr().out
    # a plane on the bottom face gives its outline, as a CAD system draws it
    bottom = tmp_path / "bottom.dxf"
    assert main(["section", str(path), "--origin", "0", "0", "-2.5", "--normal", "0", "0", "1",
                 "--out", str(bottom), "--no-progress"]) == 0
    assert "the plane lies on planar face(s)" in capsys.readouterr().out and bottom.exists()
    bad = tmp_path / "bad.dxf"
    # a plane that misses the part: one error line naming the argument and the file (it
    # printed the empty section on stdout, and damaged files met it in the fuzz run)
    assert main(["section", str(path), "--origin", "0", "0", "50", "--normal", "0", "0", "1",
                 "--out", str(bad), "--no-progress"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("surfmod section: error: origin: the plane through (0.0, 0.0, 50.0)") and "misses" in err
    assert len(err.splitlines()) == 1 and path.name in err and not bad.exists()


def test_femesh(part, tmp_path, capsys):
    import meshio

    path, solid = part
    out = tmp_path / "m.vtu"
    assert main(["femesh", str(path), "--size", "3", "--out", str(out), "--no-progress"]) == 0
    m = meshio.read(out)
    t = m.points[m.get_cells_type("tetra")]
    vol = np.abs(np.einsum("ij,ij->i", t[:, 1] - t[:, 0], np.cross(t[:, 2] - t[:, 0], t[:, 3] - t[:, 0]))).sum() / 6
    assert vol == pytest.approx(solid.volume, rel=5e-3)  # fillets become facets
    assert "tetra elements" in capsys.readouterr().out


def test_toolpath(part, tmp_path, capsys):
    path, _ = part
    out = tmp_path / "p.nc"
    assert main(["toolpath", str(path), "--tool", "ball", "--radius", "2", "--scallop", "0.05",
                 "--step", "1", "--out", str(out), "--no-progress"]) == 0
    text = out.read_text()
    assert "G21" in text and text.rstrip().endswith("%") and "M2" in text
    z = np.array([float(ln.split()[3][1:]) for ln in text.splitlines() if ln.startswith("G1 X")])
    assert z.max() == pytest.approx(2.5, abs=1e-4) and z.min() < 2.5  # top face, rolling over fillets
    assert "max gouge" in capsys.readouterr().out


@pytest.mark.parametrize("argv, msg", [
    (["toolpath", "{p}", "--radius", "0", "--scallop", "0.1", "--out", "{d}/x.nc"], "radius"),
    (["toolpath", "{p}", "--radius", "1", "--stepover", "3", "--out", "{d}/x.nc"], "stepover"),
    (["femesh", "{p}", "--size", "-1", "--out", "{d}/x.msh"], "size"),
    (["mass", "{d}/missing.step"], "no such file"),
    (["section", "{d}/junk.step", "--origin", "0", "0", "0", "--normal", "0", "0", "1", "--out", "{d}/x.dxf"], "STEP file"),
    (["section", "{p}", "--origin", "0", "0", "0", "--normal", "0", "0", "0", "--out", "{d}/x.dxf"], "plane_normal"),
])
def test_bad_input(part, tmp_path, capsys, argv, msg):
    (tmp_path / "junk.step").write_text("not step")
    args = [a.format(p=part[0], d=tmp_path) for a in argv] + ["--no-progress"]
    assert main(args) == 1
    assert msg in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["junk.step"]
