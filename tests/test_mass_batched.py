"""The part-wide passes of the mass integrals equal their face-by-face forms: p-curves read
for many faces at once, evaluated together (``PcurveTable``), and trimmed planar faces in
closed form (boundary moments) -- against the node-by-node quadrature on the corpus and
closed-form solids."""

from __future__ import annotations

import math
from dataclasses import replace

import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.occ.properties import bounding_box, vertex_mean
from surfmod.occ.pcurves import face_pcurves, faces_pcurves
from surfmod.occ.topo import faces_of
from surfmod.readback import from_face
from surfmod.inputs import to_shape
from surfmod.mass.moments import node_moments
from surfmod.readback import from_faces as _read_faces
from surfmod.mass.boundary import PcurveTable, pcurve_d1, taylor_pieces
import surfmod.mass.nodes as mg
import surfmod.mass.rules as mgrid
from surfmod.mass.nodes import face_nodes, mass_face, mass_faces
from surfmod.mass.planes import plane_moments

def _rel(a, b):
    return abs(a - b) / abs(b)


QUICK = ("occt_screw.step", "pythonocc_face_recognition_sample_part.stp")


def _part(path):
    solid = to_shape(sm.import_step(path), "obj", solid=True)
    shapes = faces_of(solid)
    return solid, shapes


def _faces(path):
    """Every face of the file, in a closed solid or not (loose faces have p-curves too)."""
    return faces_of(to_shape(sm.import_step(path), "obj"))


def _table_equals_records(path):
    shapes = _faces(path)
    kinds = set()
    for records in faces_pcurves(shapes):
        taylor_pieces(records)
        table = PcurveTable(records)
        t = np.concatenate([np.linspace(*rec["range"], 9) for rec in records])
        which = np.repeat(np.arange(len(records)), 9)
        mixed = np.random.default_rng(7).permutation(len(t))  # records interleaved
        got = table.d1(which[mixed], t[mixed])
        want = np.vstack([pcurve_d1(rec, np.linspace(*rec["range"], 9)) for rec in records])[mixed]
        assert np.array_equal(got, want), path.name  # bit for bit
        kinds |= {rec["kind"] for rec in records}
    return kinds


@pytest.mark.parametrize("name", QUICK)
def test_pcurve_table_equals_record_by_record(corpus_dir, name):
    assert _table_equals_records(corpus_dir / name)


@pytest.mark.corpus
def test_pcurve_table_equals_record_by_record_on_the_corpus(corpus_file):
    _table_equals_records(corpus_file)


def test_pcurve_table_mixes_rational_and_polynomial_splines():
    # a rational p-curve beside polynomial ones: the polynomial rows as (u, v, 1)
    circle = bd.Face(bd.Wire.make_circle(1.0)).wrapped
    spline = bd.Face(bd.Wire([bd.Spline((0, 0), (1, 1), (2, 0), (1, -1)), bd.Edge.make_line((1, -1), (0, 0))])).wrapped
    records = face_pcurves(spline) + face_pcurves(circle)
    rational = dict(records[0], weights=np.linspace(1.0, 2.0, len(records[0]["points"])))
    rational.pop("taylor", None)
    records = [records[0], rational] + records[1:]
    taylor_pieces(records)
    t = np.concatenate([np.linspace(*rec["range"], 5) for rec in records])
    which = np.repeat(np.arange(len(records)), 5)
    want = np.vstack([pcurve_d1(rec, np.linspace(*rec["range"], 5)) for rec in records])
    assert np.array_equal(PcurveTable(records).d1(which, t), want)


def test_faces_pcurves_equal_face_by_face(corpus_dir):
    _, shapes = _part(corpus_dir / QUICK[0])
    together = faces_pcurves(shapes)
    for shape, mine in zip(shapes, together):
        alone = face_pcurves(shape)
        assert [r["kind"] for r in mine] == [r["kind"] for r in alone]
        for a, b in zip(mine, alone):
            for key in ("range", "sign", "wire", "breaks", "origin", "direction", "centre", "radius", "points", "knots"):
                if key in b:
                    assert np.array_equal(a[key], b[key]), key


def _planes_equal_node_by_node(path):
    shape = to_shape(sm.import_step(path), "obj")
    shapes = faces_of(shape)
    ref = vertex_mean(shape)
    read = _read_faces(shapes)
    records = faces_pcurves(shapes)
    taylor_pieces([r for recs in records for r in recs])
    faces = [mass_face(f, recs) for f, recs in zip(read, records)]
    planes = [f for f in faces if f.plane and not f.natural]
    if not planes:
        return 0
    closed, exact = plane_moments(planes, 12, ref)
    for mf, mine, is_exact in zip(planes, closed, exact):
        ders, w, node_exact = face_nodes(mf, 12)
        nodes = node_moments(ders, w, ref)
        assert np.abs(mine - nodes).max() <= 1e-13 * np.abs(nodes).max(), path.name
        assert is_exact == node_exact
    return len(planes)


def test_trimmed_planes_in_closed_form_equal_node_by_node(corpus_dir):
    assert _planes_equal_node_by_node(corpus_dir / QUICK[1]) >= 8


@pytest.mark.corpus
def test_trimmed_planes_in_closed_form_equal_node_by_node_on_the_corpus(judged_file):
    _planes_equal_node_by_node(judged_file)


def _box_minus_cylinder_inertia(a, b, c, r, h, d):
    """Volume, centroid and inertia (about the centroid) of an a x b x c box centred at
    the origin minus a z-cylinder (radius r, height h, centred at d)."""
    def box(m, x, y, z):
        return m / 12 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])

    mb, mc = a * b * c, math.pi * r * r * h
    d = np.asarray(d, dtype=float)
    jc = mc / 12 * np.diag([3 * r * r + h * h, 3 * r * r + h * h, 6 * r * r]) + mc * (d @ d * np.eye(3) - np.outer(d, d))
    vol = mb - mc
    cen = -mc * d / vol
    j = box(mb, a, b, c) - jc - vol * (cen @ cen * np.eye(3) - np.outer(cen, cen))
    return vol, cen, j


def test_holed_plate_equals_closed_form():
    # top and bottom are planar faces trimmed by a circle: the closed-form path
    d = (1.0, 0.5, 0.0)
    part = bd.Box(4, 4, 2) - bd.Pos(*d) * bd.Cylinder(1, 2)
    vol, cen, j = _box_minus_cylinder_inertia(4, 4, 2, 1, 2, d)
    m = sm.mass_properties(part)
    assert abs(m.volume - vol) <= 1e-13 * vol
    assert np.abs(m.centroid - cen).max() <= 1e-13 * 4
    assert np.abs(m.inertia - j).max() <= 1e-12 * np.abs(j).max()
    assert m.faces["trimmed"] >= 2


def _nodes_with_and_without_tensor(mf, order=12):
    tensor = face_nodes(mf, order)
    pointwise = face_nodes(replace(mf, grid_evaluate=None, boundary={}), order)
    return tensor, pointwise


@pytest.mark.parametrize("name", QUICK)
def test_tensor_grid_evaluation_equals_point_by_point(corpus_dir, name):
    # Green's grids and natural faces on the surface's tensor evaluator: the same nodes,
    # weights and partials as evaluating every point (the screw's tori and cone: bit for bit)
    _, shapes = _part(corpus_dir / name)
    read = _read_faces(shapes)
    pcs = faces_pcurves(shapes)
    taylor_pieces([r for p in pcs for r in p])
    checked = 0
    for mf in mass_faces(read, pcs):
        if mf.plane:
            continue
        (d1, w1, e1), (d2, w2, e2) = _nodes_with_and_without_tensor(mf)
        assert e1 == e2 and np.array_equal(w1, w2)
        assert np.array_equal(d1, d2), name
        checked += 1
    assert checked >= 3


@pytest.mark.parametrize("inner", ["cheaper", "u"])
def test_tensor_grid_on_a_trimmed_cylinder_and_its_fallback_equal_point_by_point(monkeypatch, inner):
    # Green's inner integral along the axis (v) or the angle (u): the tensor's gather
    # both ways round, and with the tensor refused (TENSOR_SLACK 0) the points themselves
    if inner == "u":  # as on faces whose p-curves leave gaps: Green's inner integral along u
        monkeypatch.setattr(mg, "CLOSURE_RTOL", -1.0)
    part = bd.Cylinder(1.0, 4.0) - bd.Box(4, 4, 4).rotate(bd.Axis.X, 30).translate((0, 0, 2.5))
    side = next(mass_face(from_face(f)) for f in part.faces() if f.geom_type == bd.GeomType.CYLINDER)
    assert not side.natural and side.grid_evaluate is not None
    seen = []
    real = mgrid.GreenGrid.derivatives
    monkeypatch.setattr(mgrid.GreenGrid, "derivatives", lambda self, k, *a: seen.append(k) or real(self, k, *a))
    monkeypatch.setattr(mg, "GRID_OVERHEAD", -1e18)  # always on grids
    for slack in (mgrid.GreenGrid.TENSOR_SLACK, 0.0):  # the tensor, then point by point
        monkeypatch.setattr(mgrid.GreenGrid, "TENSOR_SLACK", slack)
        (d1, w1, _), (d2, w2, _) = _nodes_with_and_without_tensor(side)
        assert np.array_equal(w1, w2)
        assert np.abs(d1 - d2).max() <= 1e-15 * np.abs(d2).max()
    assert seen and (inner != "u" or set(seen) == {0})  # (the screw's tori take v: test above)


def test_spline_faces_are_evaluated_point_by_point():
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    face = sm.BSplineSurface(net, (3, 3), ([0] * 4 + [1] * 4, [0] * 4 + [1] * 4)).face()
    mf = mass_face(from_face(face))
    assert mf.grid_evaluate is None
    assert np.array_equal(mf.evaluate(np.array([0.2]), np.array([0.7]), 1),
                          from_face(face)._derivatives(np.array([0.2]), np.array([0.7]), 1))


@pytest.mark.parametrize("cells", [mg.GRID_BATCH_CELLS, 8])
def test_green_grids_of_many_faces_equal_face_by_face(corpus_dir, monkeypatch, cells):
    # the screw's three tori share one grids pass (or several, when the padded cells
    # are capped): every face's nodes, weights and partials as alone, bit for bit
    monkeypatch.setattr(mg, "GRID_BATCH_CELLS", cells)
    calls = []
    real = mgrid.grids_nodes
    monkeypatch.setattr(mg, "grids_nodes", lambda jobs, counts: calls.append(len(jobs)) or real(jobs, counts))
    _, shapes = _part(corpus_dir / "occt_screw.step")
    read = _read_faces(shapes)
    pcs = faces_pcurves(shapes)
    taylor_pieces([r for p in pcs for r in p])
    faces = [mf for mf in mass_faces(read, pcs) if not mf.plane]
    together = mg.faces_nodes(faces, 12)
    assert max(calls) >= (2 if cells == 8 else 3)  # the three tori together (the cone has its own counts)
    for mf, (d, w, e) in zip(faces, together):
        d1, w1, e1 = face_nodes(mf, 12)
        assert e == e1 and np.array_equal(w, w1) and np.array_equal(d, d1)


@pytest.mark.parametrize("name", QUICK + ("cadquery_red_cube_blue_cylinder.step",))
def test_face_records_visit_edges_as_the_explorer_does(corpus_dir, name):
    # wires and edges by TopoDS_Iterator: the order, orientation and p-curve of
    # TopExp_Explorer(face, WIRE) / (wire, EDGE)
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED, TopAbs_WIRE
    from OCP.TopoDS import TopoDS

    from surfmod.occ.topo import explore

    _, shapes = _part(corpus_dir / name)
    for face, records in zip(shapes, faces_pcurves(shapes)):
        want = []
        for w, wire in enumerate(explore(face, TopAbs_WIRE)):
            for e in explore(wire, TopAbs_EDGE):
                edge = TopoDS.Edge(e)
                pc = BRepAdaptor_Curve2d(edge, face)
                want.append((w, (pc.FirstParameter(), pc.LastParameter()), -1.0 if edge.Orientation() == TopAbs_REVERSED else 1.0))
        assert [(r["wire"], r["range"], r["sign"]) for r in records] == want


def _explorer_vertex_mean(shape):
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_VERTEX
    from OCP.TopoDS import TopoDS

    from surfmod.occ.topo import explore

    return np.array([BRep_Tool.Pnt_s(TopoDS.Vertex(v)).Coord() for v in explore(shape, TopAbs_VERTEX)]).mean(axis=0)


@pytest.mark.parametrize("name", QUICK + ("cadquery_red_cube_blue_cylinder.step", "pythonocc_Ventilator.stp"))
def test_vertex_mean_equals_the_explorers_visits(corpus_dir, name):
    # each distinct vertex weighted by its ancestor edges: the explorer's visits, to round-off
    solid, _ = _part(corpus_dir / name)
    want = _explorer_vertex_mean(solid)
    size = np.ptp(bounding_box(solid), axis=0).max()
    assert np.abs(vertex_mean(solid) - want).max() <= 1e-14 * size


def test_vertex_mean_weights_shared_vertices_by_their_visits():
    # a box with a cylinder boss: corners met 6 times, the boss's seam vertices otherwise;
    # a plain mean of the distinct vertices would differ
    part = bd.Box(4, 4, 2) + bd.Cylinder(1, 3).translate((1, 0, 1))
    want = _explorer_vertex_mean(part.wrapped)
    assert np.abs(vertex_mean(part.wrapped) - want).max() <= 1e-15
    distinct = np.array([tuple(v) for v in part.vertices()]).mean(axis=0)
    assert np.abs(distinct - want).max() > 1e-3


def test_moments_of_groups_equal_one_call_per_group(corpus_dir):
    # the integrands of both totals (exact and not) in one pass: each group's sums are the
    # ones its own call makes, bit for bit
    from surfmod.mass.moments import _moments_of_groups

    _, shapes = _part(corpus_dir / "occt_screw.step")
    read = _read_faces(shapes)
    pcs = faces_pcurves(shapes)
    taylor_pieces([r for p in pcs for r in p])
    nodes = [face_nodes(mf, 12)[:2] for mf in mass_faces(read, pcs) if not mf.plane]
    ders, w = np.concatenate([d for d, _ in nodes]), np.concatenate([x for _, x in nodes])
    ref = np.array([0.3, -1.0, 2.0])
    cuts = [0, len(nodes[0][1]), len(nodes[0][1]) + len(nodes[1][1]), len(w)]
    groups = _moments_of_groups(ders, w, ref, cuts)
    for g in range(3):
        assert np.array_equal(groups[g], node_moments(ders[cuts[g]:cuts[g + 1]], w[cuts[g]:cuts[g + 1]], ref))


@pytest.mark.parametrize("cut", ["disc", "holed plate", "slot"])
def test_lines_and_arcs_laid_directly_equal_the_boundary_pass(monkeypatch, cut):
    # plates with holes and rounded slots: their lines' and arcs' Gauss nodes laid without
    # boundaries() give its sums (to round-off: the nodes are the same), and the solids'
    # exact volumes
    import surfmod.mass.planes as mp

    if cut == "disc":
        part, volume = bd.Cylinder(1.5, 2.0), math.pi * 1.5**2 * 2.0
    elif cut == "holed plate":
        part = bd.Box(6, 4, 1) - bd.Cylinder(1.0, 2).translate((1.2, 0.3, 0)) - bd.Cylinder(0.5, 2).translate((-2, -1, 0))
        volume = 24 - math.pi * (1.0 + 0.25)
    else:
        slot = bd.extrude(bd.SlotCenterToCenter(3.0, 1.0), amount=2).translate((0, 0, -1))
        part, volume = bd.Box(6, 4, 1) - slot, 24 - (3.0 * 1.0 + math.pi * 0.25)
    mfs = [mass_face(from_face(f)) for f in part.faces()]
    conic = [mf for mf in mfs if mp.is_conic(mf)]
    assert conic and any(rec["kind"] == "circle" for mf in conic for rec in mf.pcurves)
    ref = np.array([0.4, -0.7, 0.2])
    for order in (12, 8):
        direct, exact = plane_moments(conic, order, ref)
        assert list(exact) == [all(r["kind"] == "line" for r in mf.pcurves) for mf in conic]
        with monkeypatch.context() as m:
            m.setattr(mp, "is_conic", lambda mf: False)  # every p-curve through boundaries()
            passed, exact_passed = plane_moments(conic, order, ref)
        assert np.abs(direct - passed).max() <= 1e-15 * np.abs(passed).max()
        assert list(exact) == list(exact_passed)
    r = sm.mass_properties(part)
    assert _rel(r.volume, volume) < 1e-13


def _spline_breaks_are_their_knots(path):
    """Every B-spline p-curve's breaks, from the knots read in bulk, are its range's ends and
    its distinct knots strictly inside, read one by one through the adaptor (periodic ones
    repeated every period), bit for bit; OCCT's own ``GeomAbs_CN`` interval bounds are
    among them (OCCT 7.9 merges the intervals of some curves of degree >= 4 with simple
    knots, koch_Follower_Gripper_Static_Part's quintics, and never splits them further)."""
    from surfmod.occ.pcurves import _intervals
    from OCP.GeomAbs import GeomAbs_CN

    shapes = _faces(path)
    splines = [r for recs in faces_pcurves(shapes) for r in recs if r["kind"] == "bspline"]
    taylor_pieces(splines)  # the breaks of those read in bulk, from their knots
    for rec in splines:
        pc = rec["adaptor"]
        b, (f, l) = pc.BSpline(), rec["range"]
        knots = np.array([b.Knot(i) for i in range(1, b.NbKnots() + 1)])
        if b.IsPeriodic():
            period = b.LastParameter() - b.FirstParameter()
            knots = np.unique((knots[None, :] + period * np.arange(-3, 4)[:, None]).ravel())
            inside = knots[(knots > f) & (knots < l)]
        else:
            inside = knots[(knots > max(f, knots[0])) & (knots < min(l, knots[-1]))]
        assert np.array_equal(rec["breaks"], np.concatenate([[f], inside, [l]])), path.name
        assert np.isin(_intervals(pc, pc.NbIntervals(GeomAbs_CN)), rec["breaks"]).all(), path.name
    return len(splines)


def test_spline_pcurve_breaks_from_knots_read_in_bulk(corpus_dir, monkeypatch):
    # the screw's helical p-curves reach past their end knots: still no adaptor read
    import surfmod.occ.pcurves as pcm

    real, read = pcm._intervals, []
    monkeypatch.setattr(pcm, "_intervals", lambda pc, n: read.append(n) or real(pc, n))
    _, shapes = _part(corpus_dir / "occt_screw.step")
    faces_pcurves(shapes)
    assert not read
    monkeypatch.undo()
    assert _spline_breaks_are_their_knots(corpus_dir / "occt_screw.step") >= 20


@pytest.mark.corpus
def test_spline_pcurve_breaks_are_their_knots_on_the_corpus(corpus_file):
    _spline_breaks_are_their_knots(corpus_file)


def test_boundary_nodes_with_span_hints_equal_the_search(corpus_dir, monkeypatch):
    # the span of each piece's middle serves all its Gauss nodes: the same values as
    # searching every node's span (the screw's helical B-spline p-curves, bit for bit)
    import surfmod.mass.nodes as mg
    from surfmod.mass.boundary import PcurveTable, boundaries

    _, shapes = _part(corpus_dir / "occt_screw.step")
    read = _read_faces(shapes)
    pcs = faces_pcurves(shapes)
    taylor_pieces([r for p in pcs for r in p])
    rules = [mg._boundary_rule(mf, 12) for mf in mass_faces(read, pcs) if not mf.natural]
    hinted = boundaries(rules)
    real = PcurveTable.d1
    monkeypatch.setattr(PcurveTable, "d1", lambda self, which, t, span=None: real(self, which, t))
    searched = boundaries(rules)
    assert sum(len(h[2]) for h in hinted) > 3000
    for h, s in zip(hinted, searched):
        assert all(np.array_equal(x, y) for x, y in zip(h[:3], s[:3])) and h[3] == s[3]


@pytest.mark.parametrize("name", QUICK)
def test_pcurve_table_subset_equals_a_table_of_those_records(corpus_dir, name):
    # the boundary pass takes its table from the rectangle test's: the same arrays, and
    # the same evaluations bit for bit
    _, shapes = _part(corpus_dir / name)
    pcs = faces_pcurves(shapes)
    records = [r for p in pcs for r in p]
    taylor_pieces(records)
    table = PcurveTable(records)
    rows = np.arange(len(records))[::-2][::-1]  # every other record, in order
    sub, fresh = table.subset(rows), PcurveTable([records[i] for i in rows])
    assert np.array_equal(sub.kind, fresh.kind)
    t = np.concatenate([np.linspace(*records[i]["range"], 9) for i in rows])
    which = np.repeat(np.arange(len(rows)), 9)
    assert np.array_equal(sub.d1(which, t), fresh.d1(which, t))
    spline = fresh.kind[which] == 2
    if spline.any():
        assert np.array_equal(sub.span_of(which[spline], t[spline]) - sub.first[which[spline]],
                              fresh.span_of(which[spline], t[spline]) - fresh.first[which[spline]])


def test_elementary_degrees_by_type_equal_direction_degree():
    import surfmod.mass.nodes as mg

    solids = [bd.Box(1, 2, 3), bd.Cylinder(1, 2), bd.Cone(2, 1, 3), bd.Sphere(1), bd.Torus(3, 1)]
    kinds = set()
    for solid in solids:
        for f in solid.faces():
            surf = from_face(f).surface
            kinds.add(type(surf))
            assert mg._degrees(surf) == (mg.direction_degree(surf, 0), mg.direction_degree(surf, 1))
    assert kinds == set(mg._ELEMENTARY_DEGREES)
