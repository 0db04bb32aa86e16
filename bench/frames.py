"""What the frames of ``make demo`` cost: the bar demo's loop time beside the time its 30
frames, animation.gif and animation.mp4 take, into ``bench/frames.md``.

    python bench/frames.py [--tree NAME=DIR ...] [--repeats 3]

Two measures, each of runs taken in turn (so that the machine's load falls on all alike),
reported as medians with the ratio of the medians:

- the renderer's process alone (``python -m rwall_fem.output.render DIR``) on the same
  frame data, with this tree's code and with each ``--tree`` (a checkout of older code,
  e.g. ``before=DIR`` from before the renderer reused one scene): wall and CPU time;
- ``rwall-fem run demos/bar_impact.toml`` with the renderer beside the loop
  (``RWALL_FEM_RENDER=worker``) and after it (``inline``): the loop time (``summary.json``)
  and the time the outputs took after the loop (``run.log``'s last line).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "demos" / "bar_impact.toml"
FOLDER = Path("/tmp/rwall_fem-bench-frames")


def _env(tree: Path, **extra: str) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    env.update(PYTHONPATH=str(tree), VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow",
               MPLBACKEND="Agg", **extra)  # fmt: skip
    return env


def _render_seconds(tree: Path, folder: Path) -> tuple[float, float]:
    """Wall time and CPU time (user + system, the renderer and its ffmpeg) of one
    drawing, s: on a machine shared with other work the CPU time is the steadier."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rwall_fem.output.render", str(folder)],
                   env=_env(tree), cwd=tree, check=True, capture_output=True)  # fmt: skip
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def _run_seconds(mode: str, folder: Path) -> tuple[float, float]:
    """The demo's loop time and the time its outputs took after the loop (s), rendering
    ``mode`` (worker or inline)."""
    subprocess.run([sys.executable, "-m", "rwall_fem", "run", str(SCENE), "--out", str(folder),
                    "--quiet"], env=_env(ROOT, RWALL_FEM_RENDER=mode), check=True)  # fmt: skip
    loop = json.loads((folder / "summary.json").read_text())["wall_seconds"]
    after = re.findall(r"outputs written ([0-9.]+) s after the time loop",
                       (folder / "run.log").read_text())  # fmt: skip
    return loop, float(after[-1])


def _median(values) -> float:
    return statistics.median(list(values))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tree", action="append", default=[], metavar="NAME=DIR")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "frames.md")
    args = parser.parse_args()
    trees = {"this tree": ROOT}
    trees.update((name, Path(path)) for name, path in (t.split("=", 1) for t in args.tree))
    loads = [os.getloadavg()[0]]
    renders: dict[str, list[tuple[float, float]]] = {name: [] for name in trees}
    runs: dict[str, list[tuple[float, float]]] = {"worker": [], "inline": []}
    for _ in range(args.repeats):
        for mode, times in runs.items():
            times.append(_run_seconds(mode, FOLDER.with_name(f"{FOLDER.name}-{mode}")))
            loads.append(os.getloadavg()[0])
        for name, tree in trees.items():
            renders[name].append(_render_seconds(tree, FOLDER.with_name(f"{FOLDER.name}-inline")))
            loads.append(os.getloadavg()[0])
    cores = len(os.sched_getaffinity(0))
    lines = [
        "# What the frames of `make demo` cost",
        "",
        f"`demos/bar_impact.toml` (10,000 hexahedra, 30 frames at 800 x 600, GIF and MP4) on "
        f"this project's {cores}-core machine, shared with other work: load average "
        f"{min(loads):.1f} to {max(loads):.1f} (median {_median(loads):.1f}) during the "
        f"measures. Medians of {args.repeats} runs of each, taken in turn; ratios of medians.",
        "",
        "The renderer's process alone (`python -m rwall_fem.output.render DIR`, the same frame "
        "data): wall time, and CPU time (with ffmpeg's), which other work disturbs less.",
        "",
        "| renderer | wall (s) | CPU (s) | wall / this tree's | each run, wall / CPU (s) |",
        "|---|---|---|---|---|",
    ]
    mine = _median(w for w, _ in renders["this tree"])
    for name, times in renders.items():
        wall, cpu = _median(w for w, _ in times), _median(c for _, c in times)
        each = ", ".join(f"{w:.2f} / {c:.2f}" for w, c in times)
        lines.append(f"| {name} | {wall:.2f} | {cpu:.2f} | {wall / mine:.2f} | {each} |")
    lines += [
        "",
        "`rwall-fem run demos/bar_impact.toml`: the time loop, and the outputs after it "
        "(frames, GIF, MP4, histories.png; `run.log`'s last line), with the renderer beside "
        "the loop (`RWALL_FEM_RENDER=worker`: it imports and reads the frames while the loop "
        "runs) and started after it (`inline`).",
        "",
        "| renderer | the time loop (s) | outputs after the loop (s) "
        "| each run, loop / after (s) |",
        "|---|---|---|---|",
    ]
    for mode, times in runs.items():
        loop, after = _median(t for t, _ in times), _median(a for _, a in times)
        each = ", ".join(f"{t:.2f} / {a:.2f}" for t, a in times)
        lines.append(f"| {mode} | {loop:.2f} | {after:.2f} | {each} |")
    args.out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
