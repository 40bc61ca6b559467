"""``sm.conformance`` and ``surfmod conformance``: any evaluator held against OCCT and the
40-digit reference (issue 35).

The reference is checked against closed forms and against itself computed afresh (the
cache in ``surfmod/conform/reference.npz`` must be the reference of the cases as they are
now); the verdict must fail an evaluator that is off by 1e-9 and pass OCCT against itself.
"""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

import surfmod as sm
from surfmod.cli import main
from surfmod.conform import adapters, cases, reference
from surfmod.nets import mp_reference

#: surfmod's evaluation paths: each must be within max(OCCT's error, 1e-12) of the 40-digit
#: reference on every stress case (nets 1e6 from the origin are evaluated about their
#: centre, crowded knots keep the patches away: surfmod/eval/local.prepare, patches.suits)
SURFMOD_PATHS = ("surfmod", "surfmod-patches", "surfmod-numpy")


@pytest.fixture(scope="module")
def stress():
    return {c.name: c for c in cases.stress_cases()}


def _few(stress, *names):
    return [stress[n] for n in names]


def sloppy(surface, u, v, order):
    """An evaluator off by one part in 1e9: it must fail."""
    return surface.derivatives(u, v, order) * (1 + 1e-9)


def positions(surface, u, v):
    return surface.points(u, v)


def test_curve_reference_is_the_closed_form_of_a_rational_quarter_circle():
    # poles (1,0), (1,1), (0,1), weights 1, 1, 2: x = (1-t²)/(1+t²), y = 2t/(1+t²)
    t = 0.3
    d = mp_reference.curve_partials([(1, 0, 0), (1, 1, 0), (0, 1, 0)], [1, 1, 2], 2, [0, 0, 0, 1, 1, 1], t)
    s = 1 + t * t
    want = [((1 - t * t) / s, 2 * t / s), (-4 * t / s**2, 2 * (1 - t * t) / s**2),
            ((12 * t * t - 4) / s**3, 4 * t * (t * t - 3) / s**3)]
    for k in range(3):
        assert [float(x) for x in d[k][:2]] == pytest.approx(want[k], rel=1e-15, abs=1e-16)


def test_cache_holds_every_shipped_case_and_matches_a_fresh_reference(stress):
    with np.load(reference.CACHE) as data:
        assert str(data["mpmath_version"]) and int(data["dps"]) == reference.DPS
        missing = [c.name for c in stress.values() if f"ref_{c.fingerprint()}" not in data.files]
    assert not missing, "regenerate: python -m surfmod.conform.reference"
    for name in ("21 x 4 bicubic, crowded u, domain below 0", "NURBS, weights 1..1e4, crowded", "curve, degree 9"):
        case = stress[name]
        few = case._replace(u=case.u[::9], v=None if case.v is None else case.v[::9])
        fresh = reference.compute(few)
        cached = reference.reference(case)[::9]
        assert np.array_equal(np.isnan(fresh), np.isnan(cached))
        assert np.array_equal(fresh[~np.isnan(fresh)], cached[~np.isnan(cached)])


def test_stress_family_covers_the_issue(stress):
    objs = [c.obj for c in stress.values()]
    degrees = {d for o in objs for d in np.atleast_1d(o.degree)}
    assert set(range(1, 10)) <= degrees and 25 in degrees
    knots = [k for o in objs for k in ([o.knots] if o.knots.__class__ is np.ndarray else o.knots)]
    spans = min(np.diff(np.unique(k)).min() / np.ptp(k) for k in knots)
    assert spans <= 1e-6
    widths = [np.ptp(np.array(o.domain).reshape(-1, 2), axis=1) for o in objs]
    assert min(map(min, widths)) <= 1.001e-3 and max(map(max, widths)) >= 1e4
    ratios = [o.weights.max() / o.weights.min() for o in objs if o.weights is not None]
    assert max(ratios) > 1e3
    assert max(np.abs(o.control_points).max() for o in objs) >= 1e6
    assert sum(c.is_curve for c in stress.values()) >= 5


@pytest.mark.parametrize("name", ["surfmod", "surfmod-patches", "surfmod-numpy", "occt", "geomdl", "splipy", "rhino3dm"])
def test_every_shipped_adapter_conforms_on_ordinary_cases(stress, name):
    if name in adapters.OPTIONAL and importlib.util.find_spec(name) is None:
        pytest.skip(adapters.missing(name))
    chosen = _few(stress, "crowded 1e-03 bicubic", "rational Bezier, weights 1..1e4", "curve, weights 1..1e4")
    table = sm.conformance(name, chosen)
    assert table.passed, table.markdown()
    orders = 0 if name == "rhino3dm" else 2
    assert {(r.case, r.order) for r in table.rows} >= {(c.name, k) for c in chosen[:2] for k in range(orders + 1)}
    assert all(r.error <= 1e-12 and r.right == "both" for r in table.rows)


@pytest.mark.parametrize("name", SURFMOD_PATHS)
def test_surfmod_conforms_on_the_whole_stress_family(stress, name):
    table = sm.conformance(name, list(stress.values()))
    assert table.passed, table.markdown()


def test_occt_loses_digits_on_a_degree_25_bezier_where_surfmod_keeps_them(stress):
    table = sm.conformance("surfmod-numpy", _few(stress, "Bezier degree 25 x 3", "Bezier curve degree 25"))
    first = [r for r in table.rows if r.order == 1]
    assert all(r.occt_error > 1e-8 and r.error < 1e-13 and r.right == "evaluator" for r in first)
    assert table.passed


def test_a_callable_of_either_signature_is_an_evaluator(stress):
    chosen = _few(stress, "crowded 1e-05 bicubic", "periodic bicubic, closed in u", "curve, crowded 1e-6")
    t0 = sm.conformance(positions, chosen, orders=0)
    assert t0.passed and [r.order for r in t0.rows] == [0, 0]  # curves are not a callable's
    t2 = sm.conformance(lambda s, u, v, order: s.derivatives(u, v, order), chosen[:1], orders=2)
    assert t2.passed and [r.order for r in t2.rows] == [0, 1, 2]


def test_a_sloppy_evaluator_fails_and_occt_is_named_right(stress):
    table = sm.conformance(sloppy, _few(stress, "crowded 1e-05 bicubic"))
    assert not table.passed
    assert [(r.order, r.right, r.ok) for r in table.rows] == [(0, "OCCT", False), (1, "OCCT", False), (2, "OCCT", False)]
    assert all(r.error == pytest.approx(1e-9, rel=0.05) for r in table.rows)  # positions: against the extent
    assert "**no**" in table.markdown() and "worse than OCCT on: crowded 1e-05 bicubic" in table.markdown()


@pytest.mark.parametrize("f, message", [
    (lambda s, u, v, order: np.zeros((u.size, 3)), r"returned shape \(36, 3\) on case 'crowded 1e-05 bicubic', expected \(36, 3, 3, 3\)"),
    (lambda s, u, v, order: np.full((u.size, order + 1, order + 1, 3), np.nan), "returned NaN or infinity"),
    (lambda s, u, v, order: 1 / 0, "raised ZeroDivisionError: division by zero"),
    (lambda s, u, v, order: "points", "returned str, not an array of floats"),
])
def test_bad_evaluators_raise_one_error_naming_it(stress, f, message):
    with pytest.raises(sm.SurfmodError, match=f"^evaluator: .*{message}"):
        sm.conformance(f, _few(stress, "crowded 1e-05 bicubic"))


@pytest.mark.parametrize("kwargs, message", [
    ({"evaluator": "nope"}, "evaluator: unknown adapter 'nope'"),
    ({"evaluator": "math:nope"}, "evaluator: cannot load 'math:nope'"),
    ({"evaluator": 3}, "evaluator: expected an adapter name or a callable"),
    ({"evaluator": "occt", "orders": 3}, "orders: expected 0, 1 or 2"),
    ({"evaluator": "occt", "cases": "bogus"}, "cases: expected 'stress'"),
    ({"evaluator": "occt", "cases": [math.pi]}, r"cases\[0\]: expected a surfmod B-spline"),
    ({"evaluator": "occt", "cases": "missing.step"}, "cases: no such file"),
])
def test_bad_arguments_raise_naming_the_argument(kwargs, message):
    with pytest.raises(sm.SurfmodError, match=f"^{message}"):
        sm.conformance(**kwargs)


def test_an_absent_library_is_a_missing_extra(monkeypatch):
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None)
    with pytest.raises(sm.MissingExtraError, match="rhino3dm is not installed"):
        sm.conformance("rhino3dm")


def test_the_faces_of_a_step_file_are_cases_over_their_bounds(tmp_path, stress):
    path = tmp_path / "part.step"
    sm.export_step(stress["crowded 1e-03 bicubic"].obj.face(), str(path))
    table = sm.conformance("surfmod-numpy", str(path), orders=1)
    assert table.passed and [r.case for r in table.rows] == ["part.step face 0"] * 2


def test_cli_exit_codes_table_and_csv(tmp_path, capsys):
    assert main(["conformance", "--evaluator", "occt", "--orders", "0", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "occt: 32 of 32 cases within max(OCCT, 1e-12)" in out
    csv = tmp_path / "rows.csv"
    code = main(["conformance", "--evaluator", "test_conformance:sloppy", "--orders", "1", "--csv", str(csv),
                 "--no-progress"])
    assert code == 1 and csv.read_text().startswith("case,order,evaluator,OCCT,right,conforms")
    assert main(["conformance", "--evaluator", "occt", "--orders", "0", "--markdown", "--no-progress"]) == 0
    assert "| case | order | evaluator | OCCT | right | conforms |" in capsys.readouterr().out


@pytest.mark.parametrize("argv, message", [
    (["--evaluator", "nope"], "evaluator: unknown adapter 'nope'"),
    (["--evaluator", "test_conformance:sloppy", "--orders", "0"], "evaluator: test_conformance:sloppy raised TypeError"),
    (["--evaluator", "occt", "--cases", "missing.step"], "cases: no such file"),
])
def test_cli_bad_input_is_one_line_and_no_file(tmp_path, capsys, argv, message):
    csv = tmp_path / "rows.csv"
    assert main(["conformance", *argv, "--csv", str(csv), "--no-progress"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"surfmod conformance: error: {message}")
    assert not csv.exists()


def test_a_shipped_library_failing_on_a_case_is_a_failing_row(stress, monkeypatch):
    def broken(obj, u, v, order):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setitem(adapters.ADAPTERS, "geomdl", adapters.Adapter("geomdl", broken))
    table = sm.conformance("geomdl", _few(stress, "crowded 1e-05 bicubic"), orders=1)
    assert not table.passed and all(np.isnan(r.error) and not r.ok for r in table.rows)
    assert table.rows[0].note == "geomdl raised ZeroDivisionError: float division by zero"


def test_reference_work_beyond_the_cap_is_refused_before_it_starts(stress):
    fresh = stress["Bezier degree 25 x 3"].obj.transformed(np.diag([2.0, 1, 1, 1]))  # not in the cache
    with pytest.raises(sm.SurfmodError, match=r"^cases: their 40-digit reference would sum 3\.74e\+03 basis terms.*max_terms=1e\+03"):
        sm.conformance("occt", [fresh], max_terms=1e3)
