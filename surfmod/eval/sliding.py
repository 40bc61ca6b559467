"""Grid positions on a big net with the two stages interleaved: each net row is contracted
with the v-basis just before the first u-point that needs it, into a ring of
:data:`RING` rows, a chunk of :data:`CHUNK` v-points at a time, and the u-points combine
their rows from the ring.

With about one u-point a span every u-point brings a new net row, so the row table of
:mod:`surfmod.eval.grid_kernels` (several MiB per block) is written to L2 and read back
row by row, four times over.  The ring (8 rows x 4 coordinates x 1024 v-points, 256 KiB)
stays in L2 instead, and rows at a block boundary are not contracted twice.  A chunk is
as long as the grid's v-blocks (:data:`surfmod.eval.local.V_BLOCK`): each net row's
coordinate planes are then read in long contiguous stretches, which the hardware
prefetchers follow from memory (a 1000x1000 net is 32 MB); chunks of 256 v-points, whose
ring fits L1, read them in 2 KiB pieces and made the grid 20 % slower (1000² points on
that net: 6.6-7.0 ms against 5.3-5.9 ms).  The sums are those of the two-stage path term
for term (the same row stage, :func:`surfmod.eval.row_stage.contract_row`, and the same
passes, :func:`surfmod.eval.position_stage.positions_pass`), so the values are identical.

Used for positions at degree <= 3 in u on sorted u-points, when the v-points fall in runs
of consecutive spans (:func:`surfmod.eval.row_stage.runs`).

>>> RING, CHUNK
(8, 1024)
"""

from __future__ import annotations

from numba import njit

from .position_stage import pass_extent, positions_pass
from .row_stage import contract_row, contract_row_pair

#: rows in the ring: a pass reads at most five (a cubic pair on rows shifted by one)
RING = 8
#: v-points a pass over the ring covers
CHUNK = 1024


@njit(cache=True, inline="always", error_model="numpy")
def suits(p, first, a0, a1, space, dim, nv, run_kinds):
    """Whether the block of u-points ``a0:a1`` goes through :func:`block_positions`:
    degree <= 3, rows in order (sorted u-points), runs of consecutive spans in v and room
    for the ring in the block's scratch ``space``."""
    if p > 3 or run_kinds.size == 0 or space.size < RING * dim * min(nv, CHUNK):
        return False
    for a in range(a0 + 1, a1):
        if first[a] < first[a - 1]:
            return False
    return True


@njit(cache=True, error_model="numpy")
def block_positions(bv, sv, q, ctrl, dim, bu, p, rational, b0, out, space, mine, a0, a1, first, vruns):
    """Positions of the u-points ``a0:a1`` (their net rows ``mine``, ``first[a]`` the place
    of u-point ``a``'s lowest among them, in order) into ``out[a0:a1, b0:b0+n_v]``, chunk
    by chunk of v-points, the rows contracted into a ring in ``space`` as the passes reach
    them."""
    bplan, planes, run_starts, run_kinds = vruns
    nv = sv.size
    chunk = min(nv, CHUNK)
    ring = space[: RING * dim * chunk].reshape((RING, 1, dim, chunk))
    flat = ring.reshape(-1)
    for c0 in range(0, nv, chunk):
        c1 = min(nv, c0 + chunk)
        ready = first[a0]  # rows of `mine` below this one are not read by the block
        a = a0
        while a < a1:
            _, top = pass_extent(first, p, a, a1)
            while ready < top:  # two rows a pass: their basis values loaded once
                contract_row_pair(bv, bplan, sv, q, ctrl, planes, mine[ready], mine[ready + 1], dim, flat,
                                  (ready % RING) * dim * chunk - c0, ((ready + 1) % RING) * dim * chunk - c0, chunk,
                                  run_starts, run_kinds, c0, c1)
                ready += 2
            if ready == top:
                r = mine[ready]
                contract_row(bv, bplan, sv, q, ctrl[r], planes[r], dim, flat, (ready % RING) * dim * chunk - c0, chunk,
                             run_starts, run_kinds, c0, c1)
                ready += 1
            a += positions_pass(bu, first, p, ring, rational, b0 + c0, out, a, a1, RING, c1 - c0)
