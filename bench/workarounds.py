"""Fixes of known bugs that would stop a benchmark run, applied only while the bug is there.

- ``rwall_fem.output.summary.deformed_bounds`` reduces NumPy arrays with the pickle-based
  ``comm.allreduce(..., MPI.MIN)``; mpi4py 3.1 (Debian 12) compares the arrays with ``<``,
  so rank 0 raises ValueError and the other ranks wait for it for ever: every run on 2
  ranks stops when its summary is written. Detected by reducing two arrays with MPI.MIN.
"""

import numpy as np
from mpi4py import MPI

import rwall_fem.output.summary as summary

__all__ = ["apply"]


def _deformed_bounds(state, comm):
    x = state.X + state.u - state.dt * state.v
    low, high = x.min(axis=0, initial=np.inf), x.max(axis=0, initial=-np.inf)
    comm.Allreduce(MPI.IN_PLACE, low, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, high, op=MPI.MAX)
    return [low.tolist(), high.tolist()]


def apply() -> list[str]:
    """Apply the fixes still needed; returns their names."""
    applied = []
    try:
        MPI.MIN(np.zeros(2), np.ones(2))
    except ValueError:
        summary.deformed_bounds = _deformed_bounds
        applied.append("summary.deformed_bounds")
    return applied
