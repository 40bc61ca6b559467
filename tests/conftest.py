"""Shared fixtures for the surfmod tests.

Hypothesis runs derandomized, so every run of the README's test command (CI's included)
checks the same examples and a failure reproduces.  To explore new random examples, run
with ``HYPOTHESIS_PROFILE=explore``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from surfmod.eval import local

# The run keeps Python's bytecode cache where the environment turns it off
# (PYTHONDONTWRITEBYTECODE): without it each xdist worker rewrote and compiled every test
# module again (6 of its 13 CPU seconds of collection) and each interpreter a test starts
# compiled surfmod again.  The workers and those interpreters inherit the environment.
if os.environ.pop("PYTHONDONTWRITEBYTECODE", None) is not None:
    sys.dont_write_bytecode = False

settings.register_profile("reproducible", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "reproducible"))


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# The real-parts corpus (tests/data/step, each file's origin and licence in its SOURCES.md).
# Tests over every file of it are marked ``corpus`` and run as the second command of .ci/run:
# ``python -m pytest -q -m corpus``; the default run (``-m "not corpus"`` in pyproject)
# keeps the quick per-file cases.
CORPUS = Path(__file__).resolve().parent / "data" / "step"


def fresh_python(script: str, env: dict | None = None) -> list[str]:
    """The words ``script`` prints when run in a fresh interpreter (nothing imported yet,
    numba's cache as configured, or as ``env`` sets it): what a first call of a process
    loads and compiles."""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True,
                          env=None if env is None else {**os.environ, **env})
    return done.stdout.split()


CORPUS_FILES = sorted(p for p in CORPUS.glob("*") if p.suffix.lower() in (".step", ".stp"))


#: the files on which the slow exact judges run (e.g. the OCCT sweep of a tool along every
#: move): the first twelve of the corpus, whose judged runs took 22 of CI's 30 minutes, and
#: three small new ones from other writers (CATIA V5, Rhino, NIST).  Every file gets the
#: cheap checks; tripling the files must not triple CI's time.
JUDGED = frozenset({
    "build123d_M6-1x12-countersunk-screw.step", "cadquery_red_cube_blue_cylinder.step", "occt_linkrods.step",
    "occt_screw.step", "pythonocc_11752.stp", "pythonocc_Ventilator.stp", "pythonocc_as1-oc-214.stp",
    "pythonocc_as1_pe_203.stp", "pythonocc_face_recognition_sample_part.stp", "trimesh_base_interface_AP214.STEP",
    "trimesh_box_sides.STEP", "trimesh_featuretype.STEP",
    "stepcode_sg1-c5-214.stp", "axom_sliced_cylinder.step", "nist_ftc_11_asme1_rb.stp",
})
JUDGED_FILES = [p for p in CORPUS_FILES if p.name in JUDGED]


# An empty corpus must fail, not skip: with no params pytest would skip every corpus test.
@pytest.fixture(params=CORPUS_FILES or [None], ids=lambda p: p.name if p else "missing")
def corpus_file(request):
    """Each STEP file of the real-parts corpus in turn."""
    if request.param is None:
        pytest.fail(f"the real-parts corpus is missing: {CORPUS}")
    return request.param


@pytest.fixture(params=JUDGED_FILES or [None], ids=lambda p: p.name if p else "missing")
def judged_file(request):
    """Each file of :data:`JUDGED` in turn: for the slow judges that compare two whole
    evaluations of a part (dense against sampled check, node by node against closed form,
    OCCT's continuity and normals at every sample, gmsh's tetrahedra); the commands
    themselves run on every file through ``corpus_file``."""
    if request.param is None:
        pytest.fail(f"the judged files of the corpus are missing: {CORPUS}")
    return request.param


@pytest.fixture(scope="session")
def corpus_dir():
    if not CORPUS_FILES:
        pytest.fail(f"the real-parts corpus is missing: {CORPUS}")
    return CORPUS


@pytest.fixture(scope="module")
def compiled_kernels():
    """Every evaluation goes through the compiled kernels, however small (by default small
    work is done in NumPy, eval/scattered.py): for the tests of the kernels themselves."""
    saved = local.COMPILED_SCATTERED, local.COMPILED_GRID
    local.COMPILED_SCATTERED = local.COMPILED_GRID = 0
    yield
    local.COMPILED_SCATTERED, local.COMPILED_GRID = saved


#: Tests of a minute or more on the 2-core CI machine (the corpus judges), then the default
#: run's of 8-20 s, the longest first: each of pytest-xdist's workers starts on its share of
#: them and the short tests fill in behind, instead of one long test arriving last and
#: leaving the other worker idle for its whole run.  xdist's ``load`` scheduling sends each
#: worker a first chunk of consecutive tests (an eighth of the run on two workers: 133 of
#: the corpus run's 1068), then the rest one short batch at a time; with the slow tests
#: simply collected first, the first worker's chunk held them all and the other ran out of
#: work (the corpus run's last 3.5 minutes on one worker).  So
#: :func:`pytest_collection_modifyitems` deals them into the workers' first chunks, the
#: longest first, in turn.
SLOW_FIRST = (
    "test_corpus_toolpath.py::test_corpus_toolpath_never_gouges[pythonocc_Ventilator.stp]",
    "test_corpus_toolpath.py::test_ventilator",
    "test_cam_job_proof.py::test_corpus_job_on_a_freeform_mould",
    "test_cam_job_proof.py::test_corpus_job_in_stock[stepcode_HEAD_BACK.stp]",
    "test_corpus_toolpath.py::test_corpus_flat_end_toolpath_never_gouges[occt_screw.step]",
    "test_cam_job_proof.py::test_corpus_job_with_a_small_tool",
    "test_mass_reference.py::test_surfmod_matches_an_independent_reference_on_every_corpus_solid[axom_boxed_sphere",
    "test_mass_reference.py::test_surfmod_matches_an_independent_reference_on_every_corpus_solid[stepcode_dm1-id",
    "test_corpus_toolpath.py::test_corpus_toolpath_never_gouges",
    "test_corpus_toolpath.py::test_corpus_flat_end",
    "test_stock_sim.py::test_corpus_finishing_path_in_stock",
    "test_cam_job_proof.py::",
    "test_fuzz.py::test_damaged_step_files_through_the_commands_corpus",
    "test_open_shells.py::test_open_shells_of_corpus_parts",
    "test_mass_green.py::test_green_grid_equals_node_by_node_on_the_corpus",
    "test_femesh.py::test_no_inverted_tet_on_any_corpus_solid",
    "test_femesh_fallback.py::test_11752",
    "test_examples.py::test_example_runs_and_writes_samples[cam_machining.py]",
    "test_examples.py::test_example_runs_and_writes_samples[fill_hole.py]",
    "test_projection_kernel.py::test_the_meshers_projections_compile_one_signature",
    "test_toolpath.py::test_the_judges_culling_finds_what_the_whole_part_finds",
    "test_cli_batch.py::test_killed_client_of_its_own_local_cluster_leaves_no_process",
    "test_cli_batch.py::test_a_worker_killed_mid_run_loses_no_other_file",
    "test_cli_batch.py::test_killed_client_leaves_no_worker_and_keeps_its_rows",
    "test_cli.py::test_console_script_runs_the_gallery",
)


def _slowness(item) -> int:
    return next((k for k, key in enumerate(SLOW_FIRST) if key in item.nodeid), len(SLOW_FIRST))


@pytest.hookimpl(trylast=True)  # after ``-m``'s deselection: the chunks are of the tests that run
def pytest_collection_modifyitems(config, items):
    """The :data:`SLOW_FIRST` tests dealt into the first chunks xdist's ``load`` scheduler
    sends its workers (worker w gets the w-th chunk of ``chunk`` consecutive tests: the
    scheduler's own arithmetic), in snake order (0, 1, 1, 0, 0, 1 …), the rest of each
    chunk and of the run in collection order (under another ``--dist`` mode, merely an
    order); without xdist, slow first."""
    items.sort(key=_slowness)  # stable
    workers = getattr(config, "workerinput", {}).get("workercount", 1)  # set on xdist's workers
    if workers < 2:
        return
    chunk = max(min(len(items) // workers // 4, config.getoption("maxschedchunk", None) or len(items)), 2)
    slow = [item for item in items if _slowness(item) < len(SLOW_FIRST)]
    rest = items[len(slow):]
    dealt = [[] for _ in range(workers)]
    for k, item in enumerate(slow):
        turn = k % (2 * workers)
        dealt[turn if turn < workers else 2 * workers - 1 - turn].append(item)
    order, overflow = [], []
    for share in dealt:
        fill = max(chunk - len(share), 0)
        order += share[:chunk] + rest[:fill]
        overflow += share[chunk:]
        rest = rest[fill:]
    items[:] = order + overflow + rest
