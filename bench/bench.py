"""Throughput benchmark of the explicit step (not a test): ``make bench`` -> bench/results.md.

Measures, in one run on this machine: cell-steps per second of the linear elastic bar on a
fixed wall at about 10k, 100k and 1M cells, tetrahedra and hexahedra, 1 and 2 MPI ranks;
the memory bandwidth (numpy triad, 1 and 2 processes) and the floor it implies for the
stiffness product; the share of a step spent around the K u kernel at 10k cells; peak
memory per cell; start-up time to the first step with the form cache warm and cold; the
2-rank parallel efficiency; and a cProfile of the step with side experiments for what
does not belong in the hot loop. Every figure is a median (or STREAM's best-of) of this run.
"""

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
PY = sys.executable
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n"]
# Bricks per side n (bar n x n x 10 n mm, 1 mm bricks): 10 n^3 hexahedra, 60 n^3 tetrahedra.
SIZES = {
    "hexahedron": {"10k": 10, "100k": 22, "1M": 46},
    "tetrahedron": {"10k": 6, "100k": 12, "1M": 26},
}
CELL_STEPS = 1.5e7  # per measurement: a few seconds of loop at any size


def sh(cmd, env=None, timeout=1800):
    started = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        sys.stderr.write(done.stdout[-2000:] + done.stderr[-4000:])
        raise RuntimeError(f"failed: {' '.join(cmd)}")
    return done.stdout, time.perf_counter() - started


def launch(ranks, args, env=None):
    prefix = [PY] if ranks == 1 else [*MPIRUN, str(ranks), PY]
    return sh([*prefix, *args], env=env)


def case(cell, n, ranks, steps, *extra, env=None):
    with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as f:
        path = f.name
    launch(
        ranks,
        [
            str(HERE / "case.py"),
            "--cell",
            cell,
            "--n",
            str(n),
            "--steps",
            str(steps),
            "--json",
            path,
            *extra,
        ],
        env=env,
    )
    record = json.loads(Path(path).read_text())
    os.unlink(path)
    return record


def machine():
    cpu = next(
        (
            line.split(":", 1)[1].strip()
            for line in open("/proc/cpuinfo")
            if line.startswith("model name")
        ),
        "?",
    )
    mem = (
        next(int(line.split()[1]) for line in open("/proc/meminfo") if line.startswith("MemTotal"))
        / 2**20
    )
    # In a child: importing petsc4py here would make this process an MPI singleton, and
    # Open MPI's mpirun refuses to start from inside one.
    versions, _ = sh(
        [
            PY,
            "-c",
            "import dolfinx; from petsc4py import PETSc; "
            "print(dolfinx.__version__, '.'.join(map(str, PETSc.Sys.getVersion())))",
        ]
    )
    dolfinx_version, petsc_version = versions.split()
    return {
        "nproc": os.cpu_count(),
        "cpu": cpu,
        "memory_gib": mem,
        "python": platform.python_version(),
        "dolfinx": dolfinx_version,
        "petsc": petsc_version,
    }


def wait_for_quiet(limit):
    """Wait (at most ``limit`` s) until no other job loads the machine; returns seconds waited.

    Two ranks on two cores beside another job measure the other job, not the solver.
    """
    started = time.perf_counter()
    while os.getloadavg()[0] > 0.5 and time.perf_counter() - started < limit:
        time.sleep(10)
    return time.perf_counter() - started


def floor_bytes(r):
    """Bytes that must move for one K u per cell: values (8 per entry), one column index
    per 3 x 3 block, block row pointers, u read and K u written (8 per row each)."""
    nnz, rows = r["nnz"], r["rows"]
    return (8 * nnz + 4 * nnz / 9 + 4 * rows / 3 + 16 * rows) / r["cells"]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", default=str(HERE / "results.md"))
    p.add_argument("--sizes", default="10k,100k,1M")
    p.add_argument(
        "--quiet-wait",
        type=float,
        default=300.0,
        help="seconds to wait at most for the 1-minute load average to fall below 0.5",
    )
    a = p.parse_args()
    waited = wait_for_quiet(a.quiet_wait)
    t_start = time.perf_counter()
    load0 = os.getloadavg()
    info = machine()
    log = print

    log("bench: memory bandwidth")
    stream = {r: json.loads(launch(r, [str(HERE / "stream.py")])[0]) for r in (1, 2)}

    results = []
    for label in a.sizes.split(","):
        for cell in ("tetrahedron", "hexahedron"):
            n = SIZES[cell][label]
            cells = (10 if cell == "hexahedron" else 60) * n**3
            steps = max(10, int(CELL_STEPS / cells))
            for ranks in (1, 2):
                log(f"bench: {cell} {label} ({cells} cells, {steps} steps) on {ranks} rank(s)")
                try:
                    r = case(cell, n, ranks, steps)
                except (RuntimeError, subprocess.TimeoutExpired) as err:
                    results.append(
                        {
                            "cell": cell,
                            "label": label,
                            "ranks": ranks,
                            "cells": cells,
                            "failed": str(err)[:200],
                        }
                    )
                    continue
                r["label"] = label
                results.append(r)

    log("bench: profile and side experiments at 10k cells (history every step)")
    profiles = {
        cell: case(
            cell, SIZES[cell]["10k"], 1, 300, "--history-interval", "1", "--profile", "--extras"
        )
        for cell in ("tetrahedron", "hexahedron")
    }

    log("bench: start-up, form cache cold then warm (SLEPc stable step)")
    startup = {}
    for cell in ("tetrahedron", "hexahedron"):
        with tempfile.TemporaryDirectory() as cache:
            env = os.environ | {"XDG_CACHE_HOME": cache}
            cold = case(cell, SIZES[cell]["10k"], 1, 20, "--real-dt", env=env)
            warm = case(cell, SIZES[cell]["10k"], 1, 20, "--real-dt", env=env)
        startup[cell] = (cold, warm)

    load1 = os.getloadavg()
    text = report(
        info,
        stream,
        results,
        profiles,
        startup,
        load0,
        load1,
        time.perf_counter() - t_start,
        waited,
    )
    Path(a.out).write_text(text)
    (Path(a.out).with_suffix(".json")).write_text(
        json.dumps(
            {
                "machine": info,
                "stream": stream,
                "results": results,
                "profiles": profiles,
                "startup": startup,
                "load": [load0, load1],
            },
            indent=1,
        )
    )
    log(text)


def _ns(r):
    return 1e9 * r["step_seconds"] / r["cells"]


def report(info, stream, results, profiles, startup, load0, load1, seconds, waited):
    L = []
    w = L.append
    w("# rwall_fem step benchmark")
    w("")
    w(
        f"Machine: {info['nproc']} cores, {info['cpu']}, {info['memory_gib']:.1f} GiB; "
        f"Python {info['python']}, DOLFINx {info['dolfinx']}, PETSc {info['petsc']}. "
        f"1-minute load average before / after: {load0[0]:.2f} / {load1[0]:.2f} after waiting "
        f"{waited:.0f} s for a quiet machine (above about 0.5, another job shares the two cores "
        f"and the 2-rank figures measure it too). Whole run: {seconds:.0f} s. Produced by "
        "`make bench` (bench/bench.py); raw figures in bench/results.json."
    )
    w("")
    w("## Memory bandwidth and the floor of one step")
    w("")
    w("| processes | numpy triad, bytes moved (40 B/element) | STREAM convention (24 B/element) |")
    w("|---|---|---|")
    for r in (1, 2):
        s = stream[r]
        moved, stream_bw = s["bandwidth_moved"] / 1e9, s["bandwidth_stream"] / 1e9
        w(f"| {r} | {moved:.1f} GB/s | {stream_bw:.1f} GB/s |")
    w("")
    w(
        "Floor of one step = bytes that must move for the stiffness product K u (matrix values, "
        "8 B per entry; one 4 B column index per 3 x 3 block; block row pointers; u read and K u "
        "written, 8 B per row each) divided by the measured bandwidth (bytes moved, with the "
        "same number of processes). The solver's PETSc matrix is BAIJ with 3 x 3 blocks, so this "
        "is the traffic it causes (AIJ would need a 4 B column index per entry, 12 B per entry "
        "instead of about 8.4)."
    )
    w("")
    w("## Throughput (linear elastic bar on a fixed wall, history every 100 steps)")
    w("")
    w(
        "| cells | cell | ranks | nnz(K) | steps | step (ms) | K u (ms) | ns / cell-step | "
        "cell-steps / s | floor (ns) | x floor | K u x floor | peak memory (B / cell) |"
    )
    w("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        if "failed" in r:
            w(
                f"| {r['cells']:,} | {r['cell'][:3]} | {r['ranks']} | failed: {r['failed']} |"
                + " |" * 9
            )
            continue
        bw = stream[r["ranks"]]["bandwidth_moved"]
        floor = 1e9 * floor_bytes(r) / bw
        ns, ns_mult = _ns(r), 1e9 * r["mult_seconds"] / r["cells"]
        w(
            f"| {r['cells']:,} | {r['cell'][:3]} | {r['ranks']} | {r['nnz']:,.0f} | {r['steps']} | "
            f"{1e3 * r['step_seconds']:.3g} | {1e3 * r['mult_seconds']:.3g} | {ns:.1f} | "
            f"{1e9 / ns:.3g} | {floor:.2f} | {ns / floor:.1f} | {ns_mult / floor:.1f} | "
            f"{r['peak_rss_bytes'] / r['cells']:,.0f} |"
        )
    w("")
    w(
        "Peak memory is the sum over ranks of the peak resident set (getrusage), start-up "
        "(gmsh, assembly) included, divided by the cells. Reference points on this machine "
        "class: a hand-written C kernel about 13 ns per tet-step on 2 cores, a PETSc block "
        "matrix multiply about 12 ns."
    )
    w("")
    w("### 2-rank parallel efficiency (step time, T1 / (2 T2))")
    w("")
    w("| cells | cell | step 1 rank (ms) | step 2 ranks (ms) | efficiency | K u efficiency |")
    w("|---|---|---|---|---|---|")
    ok = [r for r in results if "failed" not in r]
    for r1 in ok:
        if r1["ranks"] != 1:
            continue
        r2 = next(
            (r for r in ok if r["ranks"] == 2 and r["cell"] == r1["cell"] and r["n"] == r1["n"]),
            None,
        )
        if r2 is None:
            continue
        w(
            f"| {r1['cells']:,} | {r1['cell'][:3]} | {1e3 * r1['step_seconds']:.3g} | "
            f"{1e3 * r2['step_seconds']:.3g} | "
            f"{r1['step_seconds'] / (2 * r2['step_seconds']):.2f} | "
            f"{r1['mult_seconds'] / (2 * r2['mult_seconds']):.2f} |"
        )
    w("")
    w("## Where a step goes at 10k cells (1 rank)")
    w("")
    w(
        "| cell | step, history every 100 (ms) | step, history every step (ms) | K u (ms) | "
        "Python share (every 100) | Python share (every step) |"
    )
    w("|---|---|---|---|---|---|")
    for cell, prof in profiles.items():
        x = prof["extras"]
        coarse, every = x["step_seconds_every_100"], x["step_seconds_history_every_step"]
        m = x["mult_baij_seconds"]
        w(
            f"| {cell[:3]} ({prof['cells']:,}) | {1e3 * coarse:.3g} | {1e3 * every:.3g} | "
            f"{1e3 * m:.3g} | {1 - m / coarse:.0%} | {1 - m / every:.0%} |"
        )
    w("")
    w(
        "Python share = 1 - (K u alone) / (whole step): the time spent around the PETSc "
        "kernel (numpy updates, the wall, recorders, interpreter). All three times come from "
        "one process (the side experiments below): steps are medians of 3 runs of 301 steps "
        "each, the two samplings alternating; K u is the median of the BAIJ blocks."
    )
    w("")
    for cell, prof in profiles.items():
        steps = prof["steps"]
        w(
            f"### cProfile of the time loop, {cell}, {prof['cells']:,} cells, {steps} steps, "
            "history every step"
        )
        w("")
        w("| function | calls | own time (ms) | per step (us) | cumulative (ms) |")
        w("|---|---|---|---|---|")
        for row in prof["profile"][:12]:
            w(
                f"| `{row['function']}` | {row['calls']} | {1e3 * row['tottime']:.1f} | "
                f"{1e6 * row['tottime'] / steps:.0f} | {1e3 * row['cumtime']:.1f} |"
            )
        x = prof["extras"]
        step = prof["step_seconds"]
        w("")
        w(f"Side experiments ({cell}):")
        w("")
        w(
            f"- the wall treats {x['wall_nodes_default']:,} secondary nodes (every boundary node) "
            f"for {x['wall_contacts']} in contact at the end; one `constrain` costs "
            f"{1e6 * x['wall_seconds_default']:.0f} us; with the bottom face only "
            f"({x['wall_nodes_bottom']:,} nodes) the step goes from "
            f"{1e3 * x['step_seconds_every_100']:.3g} ms to "
            f"{1e3 * x['step_seconds_bottom_only']:.3g} ms (both sampling every 100 steps, "
            f"same process); sampling every step instead: "
            f"{1e3 * x['step_seconds_history_every_step']:.3g} ms."
        )
        w(
            f"- acceleration from K u: two passes (multiply, negate) "
            f"{1e6 * x['accel_two_pass_seconds']:.0f} us, one pass with a stored -1/m "
            f"{1e6 * x['accel_one_pass_seconds']:.0f} us; the velocity/position update "
            f"(4 passes) {1e6 * x['update_seconds']:.0f} us."
        )
        w(
            f"- K u with the solver's BAIJ matrix (3 x 3 blocks) "
            f"{1e3 * x['mult_baij_seconds']:.3g} ms, with an AIJ copy "
            f"{1e3 * x['mult_aij_seconds']:.3g} ms (medians, the two alternating in one process)."
        )
        w(
            f"- the stable-step eigenvalue solve (SLEPc, tol 1e-8) takes "
            f"{x['eigen_seconds_tol_1e-8']:.2f} s on this mesh; the whole step loop here takes "
            f"{step * steps:.2f} s for {steps} steps."
        )
        w("")
    w("## Start-up to the first step (10k cells, SLEPc stable step)")
    w("")
    w(
        "| cell | form cache | to first step (s) | mesh (s) | mass (s) | stiffness (s) | "
        "stable step (s) |"
    )
    w("|---|---|---|---|---|---|---|")
    for cell, pair in startup.items():
        for label, r in zip(("cold (empty XDG_CACHE_HOME)", "warm"), pair, strict=True):
            s = r["setup"]
            w(
                f"| {cell[:3]} | {label} | {r['first_step_seconds']:.2f} | "
                f"{s.get('body_mesh', 0):.2f} | {s.get('lumped_mass', 0):.2f} | "
                f"{s.get('stiffness_matrix', 0):.2f} | {s.get('critical_time_step', 0):.2f} |"
            )
    w("")
    w(
        "From the start of the benchmark process (imports included) to the end of step 0. "
        "DOLFINx 0.5 puts its FFCx/cffi cache in `$XDG_CACHE_HOME/fenics` (default "
        "`~/.cache/fenics`), read when `dolfinx.jit` is imported: a fresh temporary "
        "`XDG_CACHE_HOME` gives a cold cache, the second run in it a warm one."
    )
    w("")
    return "\n".join(L) + "\n"


if __name__ == "__main__":
    main()
