"""Multi-threaded variants of the evaluation kernels (numba ``parallel=True``): ``name_parallel``
beside each ``name_compiled``, with its signature and its chunk functions, only the chunks
shared among threads.  A chunk writes only its own part of the output, so the results equal
the single-threaded ones bit for bit.  :mod:`surfmod.eval.threads` decides when they run.
"""

from __future__ import annotations

from numba import get_thread_id, njit, prange

from .kernels import SCATTER_CHUNK
from .patches import derivatives_chunk, positions_chunk
from .scattered_compiled import scattered_chunk, scattered_positions_chunk
from .tensor_grid_compiled import tensor_grid_block


@njit(cache=True, parallel=True, error_model="numpy")
def tensor_grid_parallel(bv, bplan, sv, q, ctrl, planes, dim, bu, p, rational, binom, out, origin, scratch, ring_rows,
                         chunk, first, run_starts, run_kinds, starts):
    """:func:`~surfmod.eval.tensor_grid_compiled.tensor_grid_compiled`, a block of u-points ``starts[k]:starts[k+1]``
    per task; each thread keeps its blocks' ring in its own row of ``scratch`` (rows at a
    boundary between blocks are contracted by both)."""
    for blk in prange(starts.size - 1):
        tensor_grid_block(bv, bplan, sv, q, ctrl, planes, dim, bu, p, rational, binom, out, origin,
                          scratch[get_thread_id()], ring_rows, chunk, first, run_starts, run_kinds, starts[blk],
                          starts[blk + 1])


@njit(cache=True, parallel=True, error_model="numpy")
def scattered_positions_parallel(ku, p, kv, q, ctrl, u, v, rational, inv_u, inv_v, bucket_u, bucket_v, out,
                                 origin=None):
    """:func:`~surfmod.eval.scattered_compiled.scattered_positions_compiled`, a chunk of points per task."""
    for c in prange((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        scattered_positions_chunk(ku, p, kv, q, ctrl, u, v, rational, inv_u, inv_v, bucket_u, bucket_v, out, c,
                                  origin)


@njit(cache=True, parallel=True, error_model="numpy")
def scattered_parallel(ku, p, kv, q, ctrl, u, v, order, rational, binom, inv_u, inv_v, bucket_u, bucket_v, out,
                       origin=None):
    """:func:`~surfmod.eval.scattered_compiled.scattered_compiled`, a chunk of points per task."""
    for c in prange((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        scattered_chunk(ku, p, kv, q, ctrl, u, v, order, rational, binom, inv_u, inv_v,
                        bucket_u, bucket_v, out, c, origin)


@njit(cache=True, parallel=True, error_model="numpy")
def patch_positions_parallel(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational, bucket_u, bucket_v,
                             u, v, out, origin=None):
    """The per-span patch kernel of :mod:`surfmod.eval.patches`, a chunk of points per task."""
    for c in prange((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        positions_chunk(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational, bucket_u, bucket_v,
                        u, v, out, c, origin)


@njit(cache=True, parallel=True, error_model="numpy")
def patch_derivatives_parallel(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational, bucket_u,
                               bucket_v, u, v, out, origin=None):
    """The patch kernel for partials of :mod:`surfmod.eval.patches`, a chunk of points per task."""
    for c in prange((u.size + SCATTER_CHUNK - 1) // SCATTER_CHUNK):
        derivatives_chunk(ku, p, kv, q, n, m, coeffs, mid_u, scale_u, mid_v, scale_v, rational, bucket_u, bucket_v,
                          u, v, out, c, origin)
