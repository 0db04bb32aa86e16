"""What the frames of ``make demo`` cost: the bar demo's loop time beside the time to draw
its 30 frames, animation.gif and animation.mp4 (the renderer's whole process, as the run
starts it after the loop), medians of alternating runs, into ``bench/frames.md``.

    python bench/frames.py [--old-tree DIR] [--repeats 3]

``--old-tree``: a checkout of the code before the renderer reused one scene (864d876),
whose renderer draws the same frame data in turn with this tree's.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "demos" / "bar_impact.toml"


def _env(tree: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    env.update(PYTHONPATH=str(tree), VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old-tree", type=Path)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "frames.md")
    args = parser.parse_args()
    folder = Path("/tmp/rwall_fem-bench-frames")
    subprocess.run([sys.executable, "-m", "rwall_fem", "run", str(SCENE), "--out", str(folder),
                    "--quiet"], env=_env(ROOT), check=True)  # fmt: skip
    loop = json.loads((folder / "summary.json").read_text())["wall_seconds"]
    trees = {"this tree": ROOT, **({"before (864d876)": args.old_tree} if args.old_tree else {})}
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in trees}
    load = os.getloadavg()[0]
    for _ in range(args.repeats):
        for name, tree in trees.items():
            times[name].append(_render_seconds(tree, folder))
    load = max(load, os.getloadavg()[0])
    lines = [
        "# What the frames of `make demo` cost",
        "",
        f"`demos/bar_impact.toml` (10,000 hexahedra, 30 frames at 800 x 600, GIF and MP4) on "
        f"this project's 2-core machine (load average up to {load:.1f} from other work), "
        f"medians of {args.repeats} alternating runs of the renderer's process "
        "(`python -m rwall_fem.output.render DIR`, which the run starts after its loop): "
        "its wall time, and its CPU time (with ffmpeg's), which other work disturbs less.",
        "",
        "| renderer | frames, GIF and MP4: wall (s) | CPU (s) | each run, wall / CPU (s) "
        "| the time loop (s) |",
        "|---|---|---|---|---|",
    ]
    for name, runs in times.items():
        wall = statistics.median(w for w, _ in runs)
        cpu = statistics.median(c for _, c in runs)
        each = ", ".join(f"{w:.2f} / {c:.2f}" for w, c in runs)
        lines.append(f"| {name} | {wall:.2f} | {cpu:.2f} | {each} | {loop:.2f} |")
    args.out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
