"""The roughing proof's judge of what roughing leaves (``test_cam_job_proof.rough_rest``)
measures the tool's lowest on the exact triangles where its grid misses a step.

stepcode_HEAD_BACK's two halves meet in seams on the judge's grid lines (y 0, x 250): the
grid's nodes there read the lower side, the flat end grown by allowance and a cell
stood 0.53 mm too low at (197, 0) (OCCT cuts it with the part at (202.75, 0, 36.98)),
and five nodes 5.0008-5.025 mm from the roughing's ring counted as left.  Here the step
is a fin 0.1 mm thick between two rows of the judge's nodes: its grid sees no fin at all.
"""

from __future__ import annotations

import build123d as bd
import numpy as np
import pytest
from stock_sim import Stock, disc_top
from test_cam_job_proof import rough_rest
from test_cam_roughing_regions import rough_and_sweep

import surfmod as sm
from surfmod.cam.drop_cutter import part_triangles

R, A, MARGIN, CELL = 2.0, 0.3, 2.0, 0.25
FIN_TOP = 10.0


def plate_with_fin():
    plate = bd.Box(24, 16, 4)  # z from -2 to 2; the stock's y nodes fall on -10 + 0.25 k
    fin = bd.Pos(0, 0.15, 6) * bd.Box(12, 0.1, 8)  # y 0.1-0.2, between the nodes at 0 and 0.25
    return plate + fin


def test_disc_top_is_exact_on_planes_and_a_fin():
    corners = np.array([[-50, -50], [50, -50], [50, 50], [-50, 50]], float)
    v = np.column_stack([corners, 0.3 * corners[:, 0] + 0.1 * corners[:, 1]])
    tilted = np.array([[v[0], v[1], v[2]], [v[0], v[2], v[3]]])
    centres = np.array([[1.0, 2.0], [-3.0, 0.5]])
    want = 0.3 * centres[:, 0] + 0.1 * centres[:, 1] + 5.0 * np.hypot(0.3, 0.1)  # up the slope, on the circle
    assert disc_top(tilted, centres, 5.0) == pytest.approx(want, abs=1e-12)
    level = tilted.copy()
    level[..., 2] = 7.0
    assert np.array_equal(disc_top(level, centres, 5.0), [7.0, 7.0])  # the disc inside two triangles
    assert np.all(disc_top(level + [200.0, 0.0, 0.0], centres, 5.0) == -np.inf)
    tri, _ = part_triangles(plate_with_fin(), 0.001)
    # a disc reaching 0.01 over the fin's side (y 0.2) and one stopping 0.01 short of it
    assert disc_top(tri, np.array([[0.0, 2.29], [0.0, 2.31]]), 2.1) == pytest.approx([FIN_TOP, 2.0], abs=1e-9)


@pytest.fixture(scope="module")
def roughed(tmp_path_factory):
    rough = sm.Rough(sm.Tool("flat", R, flute_length=30), allowance=A)
    job, stock, top, _, _, tri = rough_and_sweep(plate_with_fin(), rough, MARGIN, CELL, tmp_path_factory.mktemp("fin"))
    return job, stock, top, tri


def test_the_fin_between_the_nodes_is_no_stock_left(roughed):
    job, stock, top, tri = roughed
    assert not np.any(np.isclose(stock.y, 0.15, atol=0.06)) and np.all(top < FIN_TOP - 1)  # the grid misses the fin
    rest = rough_rest(stock, top, job.operations[0], CELL, tri)
    assert rest["share"] == 0, rest["share"]
    # beside the fin the roughing kept its allowance: material up to the fin's top stays
    X, Y = stock.nodes()
    beside = (np.abs(X) < 5) & (np.abs(Y - 0.15) < 0.2)
    assert stock.top[beside].min() > FIN_TOP


def test_stock_a_level_left_is_still_found(roughed):
    job, stock, top, tri = roughed
    doctored = Stock(job.stock, CELL)
    doctored.top = stock.top.copy()
    X, Y = stock.nodes()
    # a patch of the plate beside the fin kept 1.5 stepdowns of stock (a level's rings removed)
    patch = (np.abs(X - 8) < 1) & (np.abs(Y + 5) < 1)
    doctored.top[patch] += 1.5 * job.operations[0].report["stepdown"]
    rest = rough_rest(doctored, top, job.operations[0], CELL, tri)
    assert rest["above"][patch].all() and not rest["above"][~patch].any()
