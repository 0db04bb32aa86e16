"""STREAM-triad-like memory bandwidth with numpy, on every MPI rank at once.

``a = b + s c`` in two in-place numpy passes (``np.multiply(c, s, out=a)``,
``np.add(a, b, out=a)``) over arrays far larger than the caches. Bytes counted are the
ones the passes move: 16 + 24 = 40 per element (reads and writes, no write-allocate), and
for comparison with STREAM's convention 24 per element. Best of 10 (as STREAM reports);
rank 0 prints one JSON line with the aggregate over ranks.
"""

import json
import sys
import time

import numpy as np
from mpi4py import MPI

comm = MPI.COMM_WORLD
n = int(sys.argv[1]) if len(sys.argv) > 1 else 20_000_000
a, b, c = np.zeros(n), np.ones(n), np.full(n, 2.0)
best = np.inf
for _ in range(10):
    comm.Barrier()
    t0 = time.perf_counter()
    np.multiply(c, 3.0, out=a)
    np.add(a, b, out=a)
    best = min(best, comm.allreduce(time.perf_counter() - t0, op=MPI.MAX))
if comm.rank == 0:
    total = n * comm.size
    print(
        json.dumps(
            {
                "ranks": comm.size,
                "elements_per_rank": n,
                "seconds": best,
                "bandwidth_moved": 40 * total / best,
                "bandwidth_stream": 24 * total / best,
            }
        )
    )
