"""Benchmark of the explicit step (not a test): ``make bench`` -> bench/results.md and .json.

Every measurement runs in a fresh process (bench/*.py, under mpirun for 2 ranks); within
a process the variants alternate in rounds and the figures are medians, so that ratios
come from one run on one machine:

- throughput (case.py): the old code's internal force, the PETSc BAIJ product K u, against
  the element kernels and whole steps, ns per cell-step at about 10k, 100k and 1M cells,
  tetrahedra and hexahedra (one point with physical hourglass control, and 2x2x2), 1 and
  2 ranks; the 2-rank efficiency; the time outside the kernels at 10k cells;
- the 80k-hexahedron bar scene (``rwall-fem run``): time loop and answers of the default
  and of full integration, against the old code's answers (bench/old_code.json) and, with
  ``--old-tree``, against the old code's time loop run alternately;
- cost of each material relative to linear elasticity per technology (costs.py);
- peak memory per cell of a process that builds and runs about 1M cells (memory.py);
- start-up of ``rwall-fem run`` at 10k cells by stage, cold and warm caches (startup.py);
- the Taylor rod at the demo's resolution (taylor.py): the fixed step of before (0.05 of
  the stable step at rest) against the adaptive step at 0.9, steps, loop and answers;
- what the adaptive step costs per cycle on the 80k-hexahedron bar (step_cost.py);
- memory bandwidth (stream.py), for the floor of the BAIJ product.

The machine's load average is recorded before and after; the run waits (``--quiet-wait``)
for the 1-minute load average to fall below 0.5 first.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PY = sys.executable
CLI = str(Path(PY).with_name("rwall-fem"))
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n"]
# Bricks per side n (bar n x n x 10 n mm, 1 mm bricks): 10 n^3 hexahedra, 60 n^3 tetrahedra.
SIZES = {
    "hexahedron": {"10k": 10, "100k": 22, "1M": 46},
    "tetrahedron": {"10k": 6, "100k": 12, "1M": 26},
}
CELL_STEPS = 1.5e7  # per whole-step run: about a second of loop at any size
ROUNDS = {"10k": 5, "100k": 5, "1M": 3}
TARGETS = {"physical": 80.0, "tet": 15.0}  # ns per cell-step on 1 rank
SCENE_80K = [
    "--set",
    "mesh.element_size=5e-4",
    "--set",
    "run.end_time=1e-4",
    "--set",
    "output.frames=0",
    "--set",
    "output.plot=false",
]
TECH_80K = {"physical": [], "full": ["--set", 'element.integration="full"']}


def log(*args):
    print("bench:", *args, flush=True)


def sh(cmd, env=None, timeout=3600, cwd=None):
    started = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout, cwd=cwd)
    if done.returncode != 0:
        sys.stderr.write(done.stdout[-2000:] + done.stderr[-4000:])
        raise RuntimeError(f"failed ({done.returncode}): {' '.join(cmd)}")
    return done.stdout, time.perf_counter() - started


def launch(ranks, args, env=None):
    prefix = [PY] if ranks == 1 else [*MPIRUN, str(ranks), PY]
    return sh([*prefix, *args], env=env)


def measure(script, ranks, *args, env=None):
    """Run bench/<script> with ``--json`` into a temporary file; returns the record."""
    with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as f:
        path = f.name
    try:
        launch(ranks, [str(HERE / script), *map(str, args), "--json", path], env=env)
        return json.loads(Path(path).read_text())
    finally:
        os.unlink(path)


def machine():
    cpu = next(
        (
            ln.split(":", 1)[1].strip()
            for ln in open("/proc/cpuinfo")
            if ln.startswith("model name")
        ),
        "?",
    )
    mem = next(int(ln.split()[1]) for ln in open("/proc/meminfo") if ln.startswith("MemTotal"))
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
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    return {
        "nproc": os.cpu_count(),
        "cpu": cpu,
        "memory_gib": mem / 2**20,
        "python": platform.python_version(),
        "dolfinx": dolfinx_version,
        "petsc": petsc_version,
        "commit": commit,
    }


def wait_for_quiet(limit):
    """Wait (at most ``limit`` s) until the 1-minute load average is below 0.5."""
    started = time.perf_counter()
    while os.getloadavg()[0] > 0.5 and time.perf_counter() - started < limit:
        time.sleep(15)
    return time.perf_counter() - started


# ---- the measurements -------------------------------------------------------------------


def throughput(labels):
    results = []
    for label in labels:
        for cell in ("tetrahedron", "hexahedron"):
            n = SIZES[cell][label]
            cells = (10 if cell == "hexahedron" else 60) * n**3
            steps = max(10, int(CELL_STEPS / cells))
            intervals = "1,100" if label == "10k" else "1"
            for ranks in (1, 2):
                log(f"throughput: {cell} {label} ({cells:,} cells, {steps} steps), {ranks} rank(s)")
                try:
                    r = measure(
                        "case.py",
                        ranks,
                        "--cell",
                        cell,
                        "--n",
                        n,
                        "--steps",
                        steps,
                        "--rounds",
                        ROUNDS[label],
                        "--intervals",
                        intervals,
                        "--technologies",
                        "physical,full",
                    )
                except (RuntimeError, subprocess.TimeoutExpired) as err:
                    r = {"cell": cell, "n": n, "ranks": ranks, "cells": cells, "failed": str(err)}
                r["label"] = label
                results.append(r)
    return results


def answers(summary):
    """Contact duration (s; the last contact step counts whole), wall impulse (N s) and
    rebound velocity (m/s) of a bar that fell along -z onto the plane of wall 0."""
    wall = summary["walls"][0]
    return {
        "contact_duration": wall["last_contact"] - wall["first_contact"] + summary["dt"],
        "impulse": -wall["normal_impulse"][2],
        "rebound": summary["final_momentum"][2] / summary["mass"],
    }


def run_80k(cli, scene, extra, ranks=1):
    """One run of the 80k scene by ``rwall-fem run`` (``cli``), on ``ranks`` MPI ranks."""
    with tempfile.TemporaryDirectory() as out:
        args = [scene, *SCENE_80K, *extra, "--out", out, "--quiet"]
        sh([cli, "run", *args] if ranks == 1 else [*MPIRUN, str(ranks), cli, "run", *args], cwd=out)
        summary = json.loads((Path(out) / "summary.json").read_text())
    return {
        "loop_seconds": summary["wall_seconds"],
        "steps": summary["steps"] + 1,
        "cells": summary["cells"],
        "element": summary.get("element", "Q1 hexahedra, PETSc BAIJ K u (old code)"),
        "balance_error": summary["energy"]["max_balance_error"],
        **answers(summary),
    }


def bar_80k(old_tree, rounds):
    """The 80k-hexahedron scene: old code (if given), default and full integration,
    alternating; then the default on 2 ranks once."""
    scene = str(ROOT / "demos" / "bar_impact.toml")
    runs = {}
    for i in range(rounds):
        if old_tree:
            log(f"80k scene, round {i + 1}: old code ({old_tree})")
            old_cli = str(Path(old_tree) / ".venv" / "bin" / "rwall-fem")
            old_scene = str(Path(old_tree) / "demos" / "bar_impact.toml")
            runs.setdefault("old", []).append(run_80k(old_cli, old_scene, []))
        for tech, extra in TECH_80K.items():
            log(f"80k scene, round {i + 1}: {tech}")
            runs.setdefault(tech, []).append(run_80k(CLI, scene, extra))
    log("80k scene: physical on 2 ranks")
    runs["physical, 2 ranks"] = [run_80k(CLI, scene, [], ranks=2)]
    return runs


# A start-up fix that changes no result: Open MPI's UCX transport layer, probed by MPI_Init
# even in a single process, is not needed on one machine.
OB1 = {"OMPI_MCA_pml": "ob1"}


def staged_launch(scene, out, env):
    """One launch of bench/startup.py: the stages of a start-up (s)."""
    args = [str(scene), "--out", out, "--launched", repr(time.time())]
    text, _ = sh([PY, str(HERE / "startup.py"), *args], env=env)
    return json.loads(text.strip().splitlines()[-1])


def command_launch(scene, out, env):
    """One ``rwall-fem run`` process, start to exit (s)."""
    return sh([CLI, "run", str(scene), "--out", out, "--quiet"], env=env)[1]


def startup(repeats=3):
    """Cold (fresh XDG_CACHE_HOME: no FFCx nor kernel cache) then warm launches, the warm
    ones alternating with launches under OB1; Python may write its bytecode caches, as on
    a user's machine."""
    base = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    out = {}
    for cell in ("hexahedron", "tetrahedron"):
        scene = HERE / f"startup_{cell[:3]}.toml"
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as res:
            env = base | {"XDG_CACHE_HOME": cache}
            cold = staged_launch(scene, res, env)
            warm, ob1, whole, whole_ob1 = [], [], [], []
            for _ in range(repeats):
                warm.append(staged_launch(scene, res, env))
                ob1.append(staged_launch(scene, res, env | OB1))
                whole.append(command_launch(scene, res, env))
                whole_ob1.append(command_launch(scene, res, env | OB1))
        out[cell] = {
            "cold": cold,
            "warm": {k: statistics.median(w[k] for w in warm) for k in warm[0]},
            "warm_ob1": {k: statistics.median(w[k] for w in ob1) for k in ob1[0]},
            "warm_all": warm,
            "command_seconds_warm": statistics.median(whole),
            "command_seconds_warm_ob1": statistics.median(whole_ob1),
        }
    return out


# ---- the report -------------------------------------------------------------------------


def ns(seconds, cells):
    return 1e9 * seconds / cells


def floor_baij_bytes(r):
    """Bytes one BAIJ K u must move per cell: values (8 per entry), one column index per
    3 x 3 block, block row pointers, u read and K u written (8 per row each)."""
    nnz, rows = r["nnz"], r["rows"]
    return (8 * nnz + 4 * nnz / 9 + 4 * rows / 3 + 16 * rows) / r["cells"]


def _pair(results, r1):
    return next(
        (
            r
            for r in results
            if "failed" not in r
            and r["ranks"] == 2
            and r["cell"] == r1["cell"]
            and r["n"] == r1["n"]
        ),
        None,
    )


def _techs(r):
    return list(r["technologies"])


TECH_LABEL = {
    "tet": "P1 tet",
    "full": "hex 2x2x2",
    "physical": "hex 1-pt physical",
    "stiffness": "hex 1-pt FB stiffness",
    "viscous": "hex 1-pt FB viscous",
    "none": "hex 1-pt no hourglass",
}


def report(data):
    info, load = data["machine"], data["load"]
    L = []
    w = L.append
    w("# rwall_fem benchmark")
    w("")
    w(
        f"Machine: {info['nproc']} cores, {info['cpu']}, {info['memory_gib']:.1f} GiB; Python "
        f"{info['python']}, DOLFINx {info['dolfinx']}, PETSc {info['petsc']}; commit "
        f"{info['commit']}. 1-minute load average before / after: {load[0][0]:.2f} / "
        f"{load[1][0]:.2f} (5-minute: {load[0][1]:.2f} / {load[1][1]:.2f}), after waiting "
        f"{data['waited']:.0f} s for a quiet machine. Whole run: {data['seconds']:.0f} s. "
        "Produced by `make bench` (bench/bench.py); raw figures in bench/results.json. Wall "
        "times of the slowest rank; medians over alternating rounds within one process. "
        "1-minute load average at the start of each section (the benchmark's own processes "
        "count about 1 per rank): "
        + ", ".join(f"{k} {v:.2f}" for k, v in data.get("section_loads", {}).items())
        + "."
    )
    w("")
    w("## Targets")
    w("")
    w("| target | measured | met |")
    w("|---|---|---|")
    for row in data["targets"]:
        w(f"| {row[0]} | {row[1]} | {row[2]} |")
    w("")
    sections = {
        "throughput": (_throughput_section, _outside_section),
        "bar_80k": (_bar_section,),
        "costs": (_cost_section,),
        "memory": (_memory_section,),
        "taylor": (_taylor_section,),
        "step_cost": (_step_cost_section,),
        "startup": (_startup_section,),
    }
    for key, writers in sections.items():
        if key in data:
            for section in writers:
                section(w, data)
    return "\n".join(L) + "\n"


def _throughput_section(w, data):
    results, stream = data["throughput"], data["stream"]
    w("## Throughput: ns per cell-step")
    w("")
    w(
        "The linear elastic steel bar of n x n x 10n bricks of 1 mm (hexahedra, or 6 "
        "tetrahedra per brick) on a fixed plane, 10 m/s, history sampled every step. "
        "*BAIJ K u*: the old code's internal force, the PETSc product with the assembled "
        "stiffness (3 x 3 blocks), the baseline; *kernel*: the compiled element kernel "
        "alone; *step*: a whole step of the time loop (kernel, ghost exchange, -f/m, "
        "wall, update, history); *x faster*: BAIJ K u over the kernel, and over the whole "
        "step. Peak memory: sum over ranks of the peak resident set of that process (which "
        "also holds the BAIJ matrix), per cell."
    )
    w("")
    w(
        "| cells | element | ranks | BAIJ K u | kernel | step | x faster (kernel) | "
        "x faster (step) | BAIJ floor | peak memory (B/cell) |"
    )
    w("|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        if "failed" in r:
            w(
                f"| {r['cells']:,} | {r['cell'][:3]} | {r['ranks']} | failed: "
                f"{r['failed'][:120]} |" + " |" * 6
            )
            continue
        s, c = r["seconds"], r["cells"]
        baij = ns(s["baij"], c) if "baij" in s else float("nan")
        floor = 1e9 * floor_baij_bytes(r) / stream[str(r["ranks"])]["bandwidth_moved"]
        for tech in _techs(r):
            k, st = ns(s[f"{tech}:kernel"], c), ns(s[f"{tech}:step/1"], c)
            w(
                f"| {c:,} | {TECH_LABEL[tech]} | {r['ranks']} | {baij:.1f} | {k:.1f} | "
                f"{st:.1f} | {baij / k:.1f} | {baij / st:.1f} | {floor:.1f} | "
                f"{r['peak_rss_bytes'] / c:,.0f} |"
            )
    w("")
    w(
        "BAIJ floor: the bytes the BAIJ product must move (8 B per stored value, a 4 B "
        "column index per 3 x 3 block, u read and K u written) over the memory bandwidth "
        f"(numpy triad, bytes moved: {stream['1']['bandwidth_moved'] / 1e9:.1f} GB/s on 1 "
        f"process, {stream['2']['bandwidth_moved'] / 1e9:.1f} GB/s on 2). The kernels "
        "store no matrix: they read the cell's node indices, coordinates and displacements "
        "and add into the forces, about 32 + 8 x 48 B per hexahedron from the caches, "
        "and are bound by arithmetic rather than by memory."
    )
    w("")
    w("### 2-rank parallel efficiency (T1 / (2 T2))")
    w("")
    w(
        "| cells | element | step, 1 rank (ms) | step, 2 ranks (ms) | step efficiency | "
        "kernel efficiency | BAIJ K u efficiency |"
    )
    w("|---|---|---|---|---|---|---|")
    for r1 in results:
        if "failed" in r1 or r1["ranks"] != 1:
            continue
        r2 = _pair(results, r1)
        if r2 is None:
            continue
        s1, s2 = r1["seconds"], r2["seconds"]
        for tech in _techs(r1):
            a, b = s1[f"{tech}:step/1"], s2[f"{tech}:step/1"]
            ka, kb = s1[f"{tech}:kernel"], s2[f"{tech}:kernel"]
            baij = s1["baij"] / (2 * s2["baij"]) if "baij" in s1 else float("nan")
            w(
                f"| {r1['cells']:,} | {TECH_LABEL[tech]} | {1e3 * a:.3g} | {1e3 * b:.3g} | "
                f"{a / (2 * b):.2f} | {ka / (2 * kb):.2f} | {baij:.2f} |"
            )
    w("")


def _outside_section(w, data):
    w("## Time outside the kernels (10k cells, 1 rank)")
    w("")
    w(
        "Kernel alone and whole steps alternate in one process (medians). *Outside* = 1 - "
        "kernel / step: the ghost exchange, -f/m, the wall, the update pass, the history "
        "and the Python loop around them. The phases of the step (below the table) come "
        "from a separate instrumented run of the same scene."
    )
    w("")
    w(
        "| element | cells | kernel (us) | -f/m and fill included (us) | step, history every "
        "step (us) | outside | step, history every 100 (us) | outside |"
    )
    w("|---|---|---|---|---|---|---|---|")
    for r in data["throughput"]:
        if "failed" in r or r["label"] != "10k" or r["ranks"] != 1:
            continue
        s = r["seconds"]
        for tech in _techs(r):
            k, acc = s[f"{tech}:kernel"], s[f"{tech}:accelerate"]
            one, hundred = s[f"{tech}:step/1"], s[f"{tech}:step/100"]
            w(
                f"| {TECH_LABEL[tech]} | {r['cells']:,} | {1e6 * k:.0f} | {1e6 * acc:.0f} | "
                f"{1e6 * one:.0f} | {1 - k / one:.0%} | {1e6 * hundred:.0f} | "
                f"{1 - k / hundred:.0%} |"
            )
    w("")
    for cell, record in data.get("anatomy", {}).items():
        phases = record["phases"]
        total = phases["step"]
        parts = ", ".join(
            f"{name} {1e6 * t:.0f} us ({t / total:.0%})"
            for name, t in phases.items()
            if name != "step"
        )
        w(f"- {cell}: a step of {1e6 * total:.0f} us = {parts}.")
    w("")
    for cell, record in data.get("anatomy", {}).items():
        w(f"cProfile of the loop, {cell} (own time per step; the profiler inflates Python calls):")
        w("")
        w("| function | calls | own (us / step) | cumulative (us / step) |")
        w("|---|---|---|---|")
        for row in record["profile"][:10]:
            w(
                f"| `{row['function']}` | {row['calls']} | {1e6 * row['own_per_step']:.1f} | "
                f"{1e6 * row['cumulative_per_step']:.1f} |"
            )
        w("")


def _bar_section(w, data):
    bar, old = data["bar_80k"], data["old_code"]
    w("## The 80k-hexahedron bar scene")
    w("")
    w(
        "`rwall-fem run demos/bar_impact.toml --set mesh.element_size=5e-4 --set "
        "run.end_time=1e-4 --set output.frames=0 --set output.plot=false` (10 x 10 x 100 mm "
        "steel bar, 0.5 mm hexahedra, 10 m/s onto a fixed plane, 1385 steps, history every "
        "step): time loop (the summary's wall_seconds) as the median of alternating runs, "
        "and the answers against those of the old code (commit "
        f"{old['commit']}, PETSc BAIJ K u; recorded in bench/old_code.json with its "
        "command)."
    )
    w("")
    w(
        "| code | element | ranks | loop (s), median | runs (s) | x faster than the old code "
        "(same run) | contact duration (us) | impulse (N s) | rebound (m/s) | vs old (recorded): "
        "duration, impulse, rebound |"
    )
    w("|---|---|---|---|---|---|---|---|---|---|")
    old_loop = None
    if "old" in bar:
        old_loop = statistics.median(x["loop_seconds"] for x in bar["old"])
    for name, runs in bar.items():
        r = runs[0]
        loop = statistics.median(x["loop_seconds"] for x in runs)
        faster = f"{old_loop / loop:.1f}" if old_loop else "-"
        diffs = ", ".join(
            f"{100 * (r[k] / old[k] - 1):+.4f} %"
            for k in ("contact_duration", "impulse", "rebound")
        )
        ranks = 2 if "2 ranks" in name else 1
        code = "old (c11ba60)" if name == "old" else "new"
        each = ", ".join(f"{x['loop_seconds']:.2f}" for x in runs)
        w(
            f"| {code} | {r['element']} | {ranks} | {loop:.2f} | {each} | {faster} | "
            f"{1e6 * r['contact_duration']:.4f} | {r['impulse']:.6f} | {r['rebound']:.5f} | "
            f"{diffs} |"
        )
    w(
        f"| old, recorded | Q1 hexahedra, PETSc BAIJ K u | 1 | - | - | - | "
        f"{1e6 * old['contact_duration']:.4f} | {old['impulse']:.6f} | {old['rebound']:.5f} | "
        "reference |"
    )
    w("")
    w(
        "Earlier sessions on this machine: the old code's loop took 40-47 s on this scene, "
        "OpenRadioss with a one-point hexahedron 88-98 s (measured then, not re-run here)."
    )
    w("")


def _cost_section(w, data):
    w("## Cost of each material relative to linear elasticity")
    w("")
    costs = data["costs"]
    w(
        "Per technology, ns per cell-step and the ratio to the linear elastic figure of the "
        "same technology. *Kernel*: the element kernel alone, the combinations alternating "
        "in rounds; elasto-plastic kernels in two states, every point elastic and every "
        "point in plastic flow (radial return at every point, every call). *Step*: whole "
        "steps of the bar scene (10 m/s onto a plane; the elasto-plastic bar yields at the "
        "front) with the stable-step monitors of the nonlinear materials; runs of "
        f"{costs[0]['steps']} steps, where the monitors check more often than later in a "
        "long run. Materials: steel (7850, 210 GPa, 0.3); J2 with linear hardening "
        "(250 MPa, H 1 GPa); Johnson-Cook (A 250 MPa, B 500 MPa, n 0.3, C 0.02, heating)."
    )
    w("")
    materials = list(costs[0]["materials"])
    short = {
        "linear_elastic": "linear",
        "saint_venant_kirchhoff": "SVK",
        "neo_hookean": "neo-Hookean",
        "elastic_plastic": "J2",
        "johnson_cook": "Johnson-Cook",
    }
    head = ["element", "cells", "what"] + [short[m] for m in materials]
    head += ["J2, plastic flow", "J-C, plastic flow"]
    w("| " + " | ".join(head) + " |")
    w("|" + "---|" * len(head))
    for rec in costs:
        c = rec["cells"]
        ks, ss = rec["kernel_seconds"], rec["step_seconds"]
        techs = list(dict.fromkeys(k.split(":")[0] for k in ks))
        for tech in techs:
            base = ks[f"{tech}:linear_elastic:elastic"]
            figures = [ks[f"{tech}:{m}:elastic"] for m in materials]
            figures += [ks[f"{tech}:{m}:plastic"] for m in ("elastic_plastic", "johnson_cook")]
            cells = [f"{ns(x, c):.0f} ({x / base:.2f}x)" for x in figures]
            w(f"| {TECH_LABEL[tech]} | {c:,} | kernel | " + " | ".join(cells) + " |")
            if f"{tech}:linear_elastic" in ss:
                sbase = ss[f"{tech}:linear_elastic"]
                figures = [ss[f"{tech}:{m}"] for m in materials]
                cells = [f"{ns(x, c):.0f} ({x / sbase:.2f}x)" for x in figures]
                w(f"| {TECH_LABEL[tech]} | {c:,} | step | " + " | ".join(cells) + " | | |")
    w("")


def _memory_section(w, data):
    w("## Memory per cell")
    w("")
    w(
        "Peak resident set (getrusage) of a process that builds a body of about 1M cells "
        "(gmsh, the mass, the kernels, the SLEPc stable step) and runs it for a few steps "
        "with the history every step, divided by the cells; then, after each stage, the "
        "resident set and its peak so far. *In use*: the resident set of a second run of "
        "the hexahedra that hands freed memory back to the system (malloc_trim) before "
        "each reading; the difference to *resident* is memory freed but kept by malloc."
    )
    w("")
    live = {s["stage"]: s["rss"] for s in data.get("memory_live", {}).get("stages", [])}
    for rec in data["memory"]:
        c = rec["cells"]
        w(
            f"**{rec['technology']}**, {c:,} cells, {rec['nodes']:,} nodes, {rec['ranks']} "
            f"rank(s): peak {rec['peak_rss_bytes'] / c:,.0f} B per cell "
            f"({rec['peak_rss_bytes'] / 2**20:,.0f} MiB)."
        )
        w("")
        hexes = rec["cell"] == "hexahedron" and live
        w(
            "| after | resident (MiB) | peak so far (MiB) | peak so far (B/cell) | stage (s) |"
            + (" in use (MiB) | in use (B/cell) |" if hexes else "")
        )
        w("|---|---|---|---|---|" + ("---|---|" if hexes else ""))
        for s in rec["stages"]:
            extra = ""
            if hexes and s["stage"] in live:
                extra = f" {live[s['stage']] / 2**20:,.0f} | {live[s['stage']] / c:,.0f} |"
            w(
                f"| {s['stage']} | {s['rss'] / 2**20:,.0f} | {s['peak'] / 2**20:,.0f} | "
                f"{s['peak'] / c:,.0f} | {s['seconds']:.2f} |{extra}"
            )
        w("")


# The Taylor rod's two runs: the fixed step of before and the adaptive step.
TAYLOR = {"fixed": ("fixed", 0.05), "adaptive": ("adaptive", 0.9)}
OPENRADIOSS_TAYLOR_CYCLES = 14845  # OpenRadioss on the same mesh (issue 19)


def _taylor_runs(data):
    """The Taylor records by run; an older results.json holds one run, of the fixed step."""
    t = data["taylor"]
    return {"fixed": t} if "element" in t else t


def _taylor_section(w, data):
    runs = _taylor_runs(data)
    first = next(iter(runs.values()))
    w("## The Taylor rod at the demo's resolution")
    w("")
    w(
        f"Copper rod (radius 3.2 mm, length 32.4 mm, 227 m/s onto a plane, J2 with linear "
        f"hardening, 80 us), element_size {1e3 * first['element_size']:g} mm, history every "
        f"{first['history_interval']} steps, {first['ranks']} rank: {first['element']}, "
        f"{first['cells']:,} cells; the published answers are a final length of 21.42-21.66 "
        "mm and a mushroom radius of 7.0-7.22 mm. *Fixed*: run.time_step = 'fixed' at "
        "dt_scale 0.05 (0.05 of the stable step at rest for the whole run, the setting of "
        "before the adaptive step); *adaptive*: run.time_step = 'adaptive' at dt_scale 0.9 "
        f"(OpenRadioss takes {OPENRADIOSS_TAYLOR_CYCLES:,} cycles on this mesh). One run each, "
        "in fresh processes, one after the other."
    )
    w("")
    w(
        "| step | dt_scale | steps | time loop (s) | per cell-step (ns) | set-up (s) | status | "
        "final length (mm) | mushroom radius (mm) | largest plastic strain | smallest, largest "
        "step (s) |"
    )
    w("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, t in runs.items():
        steps = t.get("time_steps", {})
        span = (
            f"{steps['smallest']:.3g}, {steps['largest']:.3g}"
            if steps.get("smallest") is not None
            else "-"
        )
        w(
            f"| {t.get('time_step', name)} | {t['dt_scale']:g} | {t['steps']:,} | "
            f"{t['loop_seconds']:.1f} | {ns(t['loop_seconds'], t['cells'] * t['steps']):.0f} | "
            f"{t['setup_seconds']:.1f} | {t['status']} | {t['final_length_mm']:.2f} | "
            f"{t['mushroom_radius_mm']:.2f} | {t['max_plastic_strain']:.2f} | {span} |"
        )
    if {"fixed", "adaptive"} <= runs.keys():
        f, a = runs["fixed"], runs["adaptive"]
        w("")
        w(
            f"Adaptive against fixed: {f['steps'] / a['steps']:.2f}x fewer steps, "
            f"{f['loop_seconds'] / a['loop_seconds']:.2f}x less loop time, "
            f"{(a['loop_seconds'] / a['steps']) / (f['loop_seconds'] / f['steps']):.2f}x the "
            "time per step; final length "
            f"{100 * (a['final_length_mm'] / f['final_length_mm'] - 1):+.2f} %, mushroom radius "
            f"{100 * (a['mushroom_radius_mm'] / f['mushroom_radius_mm'] - 1):+.2f} %."
        )
    w("")


def _step_cost_section(w, data):
    c = data["step_cost"]
    sec = c["seconds"]
    w("## What the adaptive step costs per cycle (80k-hexahedron bar)")
    w("")
    w(
        f"The 80k scene ({c['cells']:,} one-point hexahedra, {c['ranks']} rank), built once; "
        "medians of alternating rounds in one process (bench/step_cost.py). *Fixed* and "
        "*adaptive*: whole steps of the time loop, run.time_step 'fixed' and 'adaptive' at "
        "dt_scale 0.9. A linear elastic body's stable step does not change: its adaptive "
        "step estimates the cells once, and each cycle only chooses the step. A body whose "
        "step varies (any other material, mass scaling) also pays, each cycle, the cells' "
        "estimates in the kernel pass and the booking of the energy correction of a varying "
        "step in the update pass: measured apart on the final state."
    )
    w("")
    step = sec["fixed"]
    parts = {
        "the estimates (kernel estimating - kernel)": sec["kernel, estimating"] - sec["kernel"],
        "the energy correction (update booking - update)": sec["update, booking"] - sec["update"],
        "the choice of the step (choose)": sec["choose"],
    }
    w("| what | us per step | % of a fixed step |")
    w("|---|---|---|")
    for name in ("fixed", "adaptive", "kernel", "kernel, estimating", "update",
                 "update, booking", "choose"):  # fmt: skip
        w(f"| {name} | {1e6 * sec[name]:.1f} | {100 * sec[name] / step:.1f} |")
    w(
        f"| adaptive - fixed (this linear elastic bar) | {1e6 * (sec['adaptive'] - step):.1f} | "
        f"{100 * (sec['adaptive'] - step) / step:.1f} |"
    )
    for name, t in parts.items():
        w(f"| {name} | {1e6 * t:.1f} | {100 * t / step:.1f} |")
    total = sum(parts.values())
    w(f"| **a varying step, per cycle** | {1e6 * total:.1f} | {100 * total / step:.1f} |")
    w("")


STAGES = [
    "python",
    "import mpi4py",
    "import petsc4py",
    "import dolfinx",
    "import rwall_fem",
    "scene",
    "meshing",
    "space and mass",
    "kernels",
    "stable step: SLEPc",
    "stable step: edges",
    "rest of set-up",
    "first step",
]


def _startup_section(w, data):
    w("## Start-up: from the launch to the end of the first step (10k cells)")
    w("")
    w(
        "`rwall-fem run` (its entry point, `rwall_fem.cli.main`) on the bar of 10 x 10 x "
        "100 1 mm hexahedra (or 12,960 tetrahedra), the stable step from SLEPc. *Cold*: a "
        "fresh `XDG_CACHE_HOME`, so FFCx compiles the lumped-mass form and gcc the element "
        "kernels; *warm*: the next launches (median of 3); *warm, ob1*: the same with "
        "`OMPI_MCA_pml=ob1` in the environment (Open MPI then skips the UCX transport that "
        "a single machine does not use; no result changes), alternating with them. "
        "*Python*: interpreter start to the script's first line; *meshing* (gmsh) includes "
        "the distribution by DOLFINx (given beside it). *Command*: the whole `rwall-fem run` "
        "process, start to exit."
    )
    w("")
    st = data["startup"]
    kinds = [k for k in ("cold", "warm", "warm_ob1") if k in next(iter(st.values()))]
    head = ["stage"] + [f"{cell[:3]} {kind.replace('_', ', ')}" for cell in st for kind in kinds]
    w("| " + " | ".join(head) + " |")
    w("|" + "---|" * len(head))
    rows = STAGES + ["meshing: distribution (DOLFINx)", "launch to first step"]
    for stage in rows:
        cells = [f"{st[cell][kind].get(stage, 0.0):.3f}" for cell in st for kind in kinds]
        name = f"**{stage}**" if stage == "launch to first step" else stage
        w(f"| {name} | " + " | ".join(cells) + " |")
    command = {"cold": "-", "warm": "command_seconds_warm", "warm_ob1": "command_seconds_warm_ob1"}
    cells = [
        "-" if kind == "cold" else f"{st[cell][command[kind]]:.3f}" for cell in st for kind in kinds
    ]
    w("| command, start to exit | " + " | ".join(cells) + " |")
    w("")


def targets(data):
    """(target, measured, met) rows from the figures of the sections that were run."""
    rows = []
    for check in (
        _target_throughput,
        _target_bar,
        _target_parallel,
        _target_outside,
        _target_memory,
        _target_costs,
        _target_startup,
        _target_taylor,
        _target_step_cost,
    ):
        try:
            rows += check(data)
        except KeyError:  # a section not run (bench.py --only)
            pass
    return rows


def _target_throughput(data):
    rows = []
    by = {(r["cell"], r["label"], r["ranks"]): r for r in data["throughput"] if "failed" not in r}
    for tech, cell, limit in (("physical", "hexahedron", 80.0), ("tet", "tetrahedron", 15.0)):
        figures = []
        for label in ("10k", "100k", "1M"):
            r = by.get((cell, label, 1))
            if r:
                figures.append(
                    (
                        label,
                        ns(r["seconds"][f"{tech}:kernel"], r["cells"]),
                        ns(r["seconds"][f"{tech}:step/1"], r["cells"]),
                    )
                )
        text = "; ".join(f"{lb}: kernel {k:.0f}, step {s:.0f}" for lb, k, s in figures)
        met_k = all(k <= limit for _, k, _ in figures)
        met_s = all(s <= limit for _, _, s in figures)
        rows.append(
            (
                f"{TECH_LABEL[tech]}: <= {limit:g} ns per cell-step, 1 rank",
                text,
                f"kernel: {'yes' if met_k else 'no'}; step: {'yes' if met_s else 'no'}",
            )
        )
    return rows


def _target_bar(data):
    rows = []
    bar = data["bar_80k"]
    loop = statistics.median(x["loop_seconds"] for x in bar["physical"])
    old = data["old_code"]
    if "old" in bar:
        old_loop = statistics.median(x["loop_seconds"] for x in bar["old"])
        speed = f", old code {old_loop:.1f} s in the same run: {old_loop / loop:.1f}x"
        fast = old_loop / loop >= 4
    else:
        speed, fast = " (old code not re-run)", loop <= 10
    rows.append(
        (
            "80k-hexahedron scene: <= 10 s of time loop on 1 rank, >= 4x faster",
            f"{loop:.2f} s{speed}",
            "yes" if loop <= 10 and fast else "no",
        )
    )
    worst = max(
        abs(r[k] / old[k] - 1)
        for name in ("physical", "full")
        for r in bar[name]
        for k in ("contact_duration", "impulse", "rebound")
    )
    rows.append(
        (
            "80k scene answers within 0.5 % of the old code's (default and full)",
            f"largest difference {100 * worst:.2g} %",
            "yes" if worst <= 0.005 else "no",
        )
    )
    return rows


def _target_parallel(data):
    effs = []
    for r1 in data["throughput"]:
        if "failed" in r1 or r1["ranks"] != 1 or r1["label"] == "10k":
            continue
        r2 = _pair(data["throughput"], r1)
        if r2:
            for tech in _techs(r1):
                a, b = r1["seconds"][f"{tech}:step/1"], r2["seconds"][f"{tech}:step/1"]
                effs.append((f"{r1['label']} {TECH_LABEL[tech]}", a / (2 * b)))
    return [
        (
            "2-rank efficiency >= 80 % at >= 100k cells (whole step)",
            "; ".join(f"{n}: {e:.0%}" for n, e in effs),
            "yes" if effs and min(e for _, e in effs) >= 0.8 else "no",
        )
    ]


def _target_outside(data):
    outs = []
    for r in data["throughput"]:
        if "failed" in r or r["label"] != "10k" or r["ranks"] != 1:
            continue
        for tech in _techs(r):
            s = r["seconds"]
            outs.append((TECH_LABEL[tech], 1 - s[f"{tech}:kernel"] / s[f"{tech}:step/1"]))
    worst = max(o for _, o in outs) if outs else float("inf")
    return [
        (
            "time outside the kernels at 10k cells, history every step: < 10 % (kernels), "
            "<= 15 % (issue 19)",
            "; ".join(f"{n}: {o:.0%}" for n, o in outs),
            f"10 %: {'yes' if worst < 0.1 else 'no'}; 15 %: {'yes' if worst <= 0.15 else 'no'}",
        )
    ]


def _target_taylor(data):
    runs = _taylor_runs(data)
    f, a = runs["fixed"], runs["adaptive"]
    faster = f["loop_seconds"] / a["loop_seconds"]
    worst = max(abs(a[k] / f[k] - 1) for k in ("final_length_mm", "mushroom_radius_mm"))
    return [
        (
            "Taylor rod 0.4 mm, 1 rank: adaptive (0.9) >= 4x less loop time than fixed "
            f"(0.05), answers within 0.5 %, steps <= OpenRadioss's {OPENRADIOSS_TAYLOR_CYCLES:,}",
            f"{a['steps']:,} steps against {f['steps']:,}; loop {a['loop_seconds']:.1f} s "
            f"against {f['loop_seconds']:.1f} s: {faster:.2f}x; answers within "
            f"{100 * worst:.2f} %",
            f"4x: {'yes' if faster >= 4 else 'no'}; answers: {'yes' if worst <= 0.005 else 'no'}"
            f"; steps: {'yes' if a['steps'] <= OPENRADIOSS_TAYLOR_CYCLES else 'no'}",
        )
    ]


def _target_step_cost(data):
    sec = data["step_cost"]["seconds"]
    cycle = (
        sec["kernel, estimating"] - sec["kernel"] + sec["update, booking"] - sec["update"]
        + sec["choose"]
    )  # fmt: skip
    share = cycle / sec["fixed"]
    return [
        (
            "the adaptive step's per-cycle cost <= 5 % of a step (80k-hexahedron bar)",
            f"{1e6 * cycle:.0f} us of a {1e3 * sec['fixed']:.2f} ms step: {share:.1%} (a varying "
            f"step; this linear elastic bar's adaptive step: "
            f"{(sec['adaptive'] - sec['fixed']) / sec['fixed']:+.1%})",
            "yes" if share <= 0.05 else "no",
        )
    ]


def _target_costs(data):
    hyper, plastic = [], []
    for rec in data["costs"]:
        ks = rec["kernel_seconds"]
        for tech in dict.fromkeys(k.split(":")[0] for k in ks):
            base = ks[f"{tech}:linear_elastic:elastic"]
            hyper.append(
                (
                    tech,
                    max(
                        ks[f"{tech}:{m}:elastic"] / base
                        for m in ("saint_venant_kirchhoff", "neo_hookean")
                    ),
                )
            )
            plastic.append((tech, ks[f"{tech}:elastic_plastic:plastic"] / base))
    rows = [
        (
            "hyperelastic (SVK, neo-Hookean) <= 2x linear, same technology (kernel)",
            "; ".join(f"{TECH_LABEL[t]} {x:.2f}x" for t, x in hyper),
            "yes"
            if max(x for _, x in hyper) <= 2
            else "all but " + ", ".join(TECH_LABEL[t] for t, x in hyper if x > 2),
        )
    ]
    default = dict(plastic).get("physical")
    rows.append(
        (
            "J2 <= 2x linear with one-point hexahedra (kernel, every point in plastic "
            "flow; default hourglass form)",
            "; ".join(f"{TECH_LABEL[t]} {x:.3f}x" for t, x in plastic),
            "yes (default)" if default is not None and default <= 2 else "no",
        )
    )
    return rows


def _target_memory(data):
    hexes = [m for m in data["memory"] if m["cell"] == "hexahedron"]
    per = hexes[0]["peak_rss_bytes"] / hexes[0]["cells"]
    text = f"peak {per:,.0f} B"
    live = data.get("memory_live")
    if live:
        used = live["stages"][-1]["rss"] / live["cells"]
        text += f"; in use during the time loop {used:,.0f} B"
    return [
        (
            "memory <= 1 kB per hexahedron (~1M cells)",
            text,
            "peak: "
            + ("yes" if per <= 1000 else "no")
            + (f"; in use: {'yes' if used <= 1000 else 'no'}" if live else ""),
        )
    ]


def _target_startup(data):
    st = data["startup"]
    figures = [
        (cell, kind, st[cell][kind]["launch to first step"])
        for cell in st
        for kind in ("warm", "warm_ob1")
        if kind in st[cell]
    ]
    text = "; ".join(f"{cell[:3]} {kind.replace('_', ', ')} {t:.2f} s" for cell, kind, t in figures)
    plain = max(t for _, kind, t in figures if kind == "warm")
    return [
        (
            "start-up <= 1 s at 10k cells, warm caches (launch to first step)",
            text,
            "yes" if plain <= 1 else "no",
        )
    ]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", default=str(HERE / "results.md"))
    p.add_argument("--sizes", default="10k,100k,1M")
    p.add_argument("--old-tree", help="a worktree of the old code (c11ba60) with its .venv")
    p.add_argument("--rounds-80k", type=int, default=3)
    p.add_argument(
        "--quiet-wait",
        type=float,
        default=1800.0,
        help="seconds to wait at most for the 1-minute load average to fall below 0.5",
    )
    p.add_argument("--only", help="comma-separated sections, for development")
    p.add_argument(
        "--smoke", action="store_true", help="tiny sizes: checks the script, not the code"
    )
    p.add_argument("--from-json", help="write the report of an earlier run's results.json")
    a = p.parse_args()
    if a.from_json:
        data = json.loads(Path(a.from_json).read_text())
        data["targets"] = targets(data)
        Path(a.out).write_text(report(data))
        return
    if a.smoke:
        global SCENE_80K
        SCENE_80K = [x.replace("5e-4", "2e-3") for x in SCENE_80K]
        a.sizes, a.rounds_80k = "10k", 1
    only = set(a.only.split(",")) if a.only else None

    def wanted(name):
        if only is None or name in only:
            data.setdefault("section_loads", {})[name] = os.getloadavg()[0]
            return True
        return False

    waited = wait_for_quiet(a.quiet_wait)
    t_start = time.perf_counter()
    data = {"machine": machine(), "waited": waited, "load": [os.getloadavg()]}
    data["old_code"] = json.loads((HERE / "old_code.json").read_text())
    log("memory bandwidth")
    data["stream"] = {str(r): json.loads(launch(r, [str(HERE / "stream.py")])[0]) for r in (1, 2)}
    if wanted("throughput"):
        data["throughput"] = throughput(a.sizes.split(","))
        log("anatomy of a step at 10k cells")
        data["anatomy"] = {
            cell: measure("anatomy.py", 1, "--cell", cell, "--n", SIZES[cell]["10k"])
            for cell in ("hexahedron", "tetrahedron")
        }
    if wanted("bar"):
        data["bar_80k"] = bar_80k(a.old_tree, a.rounds_80k)
    if wanted("costs"):
        log("material costs")
        data["costs"] = [
            measure(
                "costs.py",
                1,
                "--cell",
                cell,
                "--n",
                SIZES[cell]["10k" if a.smoke else "100k"],
                "--step-technologies",
                techs,
            )
            for cell, techs in (("hexahedron", "full,physical,stiffness"), ("tetrahedron", "tet"))
        ]
    if wanted("memory"):
        log("memory at 1M cells")
        data["memory"] = [
            measure("memory.py", 1, "--cell", cell, "--n", SIZES[cell]["10k" if a.smoke else "1M"])
            for cell in ("hexahedron", "tetrahedron")
        ]
        n = SIZES["hexahedron"]["10k" if a.smoke else "1M"]
        data["memory_live"] = measure("memory.py", 1, "--n", n, "--trim")
    if wanted("startup"):
        log("start-up")
        data["startup"] = startup()
    if wanted("step_cost"):
        log("the adaptive step's cost per cycle, 80k hexahedra")
        smoke = ["--element-size", "2e-3", "--steps", "20", "--rounds", "1", "--repeats", "3"]
        smoke = smoke if a.smoke else []
        data["step_cost"] = measure("step_cost.py", 1, *smoke)
    if wanted("taylor"):
        data["taylor"] = {}
        for name, (mode, scale) in TAYLOR.items():
            log(f"Taylor rod: {name} step, dt_scale {scale}")
            smoke = ["--element-size", "1.6e-3"] if a.smoke else []
            args = ["--time-step", mode, "--dt-scale", scale, *smoke]
            data["taylor"][name] = measure("taylor.py", 1, *args)
    data["load"].append(os.getloadavg())
    data["seconds"] = time.perf_counter() - t_start
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.with_suffix(".json").write_text(json.dumps(data, indent=1))
    data["targets"] = targets(data)
    out.write_text(report(data))
    out.with_suffix(".json").write_text(json.dumps(data, indent=1))
    print(out.read_text())


if __name__ == "__main__":
    main()
