"""Command line.

- ``rwall-fem run SCENE [--out DIR] [--set key=value ...] [--quiet] [--resume]``: run a
  scene, or with ``--resume`` continue the run whose checkpoint is in DIR;
- ``rwall-fem check SCENE [--set ...]``: validate it and print what would run;
- ``rwall-fem render DIR [--color ...]``: draw the frames of a results folder again;
- ``rwall-fem study [--quick] [--out DIR]``: what accuracy costs in time (:mod:`rwall_fem.study`).

Exit codes: 0 done, 2 bad input (one line on stderr, no traceback; also a checkpoint
that does not fit the scene), 3 run stopped by a guard or by SIGTERM (one line on
stderr; the outputs up to the stop are kept, and a checkpoint of the step), 4 an output
could not be written at the end of the run (one line on stderr; the others are written).
"""

from __future__ import annotations

import argparse
import logging
import sys
import time

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    from rwall_fem import __version__
    from rwall_fem.output.render import COLORS

    parser = argparse.ArgumentParser(
        prog="rwall-fem", description="Solid bodies striking rigid walls (explicit FEM on DOLFINx)."
    )
    parser.add_argument("--version", action="version", version=f"rwall-fem {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="run a scene")
    check = commands.add_parser("check", help="validate a scene and print what would run")
    for sub in (run, check):
        sub.add_argument("scene", help="scene file (TOML)")
        sub.add_argument(
            "--set",
            dest="overrides",
            action="append",
            default=[],
            metavar="KEY=VALUE",
            help="override a scene key, value read as TOML (e.g. mesh.element_size=5e-4)",
        )
    run.add_argument("--out", help="results directory (default: the scene's output.directory)")
    run.add_argument("--quiet", action="store_true", help="print only errors")
    run.add_argument(
        "--resume",
        action="store_true",
        help="continue the run whose checkpoint is in the results directory (/RFILE)",
    )
    render = commands.add_parser("render", help="draw the frames of a results folder again")
    render.add_argument("directory", help="results folder of a run with output.frames > 0")
    render.add_argument("--color", default=COLORS[0], choices=COLORS)
    study = commands.add_parser("study", help="accuracy against wall time, on exact references")
    study.add_argument("--quick", action="store_true", help="coarse levels only (< 2 minutes)")
    study.add_argument("--out", default="results/study", help="results directory")
    args = parser.parse_args(argv)
    if args.command == "study":
        from rwall_fem.study import run_study

        run_study(args.out, quick=args.quick)
        return 0
    if args.command == "render":
        return _render(args.directory, args.color)

    from mpi4py import MPI

    from rwall_fem.checkpoint import CheckpointError
    from rwall_fem.kernels import KernelBuildError
    from rwall_fem.output import OutputError
    from rwall_fem.scene import SceneError

    comm = MPI.COMM_WORLD
    quiet = getattr(args, "quiet", False)
    logging.getLogger().setLevel(logging.WARNING)  # the form compiler logs at INFO
    log = logging.getLogger("rwall_fem")
    for old in list(log.handlers):  # main() may run more than once in a process (tests)
        log.removeHandler(old)
    handler = logging.StreamHandler(sys.stdout)
    handler.setFormatter(logging.Formatter("rwall-fem: %(message)s"))
    log.addHandler(handler)
    log.propagate = False
    log.setLevel(logging.WARNING if quiet or comm.rank != 0 else logging.INFO)
    try:
        if args.command == "check":
            return _check(args.scene, args.overrides, comm)
        summary = _run(args.scene, args.out, args.overrides, comm, quiet, args.resume)
    except (SceneError, CheckpointError, KernelBuildError) as err:
        if comm.rank == 0:
            print(f"rwall-fem: error: {err}", file=sys.stderr)
        return 2
    except (OutputError, OSError) as err:
        print(f"rwall-fem: error: outputs: {err}", file=sys.stderr)
        return 4
    if summary["status"] != "done":
        if comm.rank == 0:
            print(f"rwall-fem: stopped: {summary['reason']}", file=sys.stderr)
        return 3
    if comm.rank == 0 and not quiet:
        e = summary["energy"]
        print(
            f"rwall-fem: done: {summary['steps']} steps of {summary['dt']:.4g} s on "
            f"{summary['ranks']} rank(s) in {summary['wall_seconds']:.2f} s; "
            f"max energy balance error {e['max_balance_error']:.2e}"
        )
    return 0


def _run(scene_file, out, overrides, comm, quiet: bool, resume: bool) -> dict:
    from rwall_fem.build import build_simulation
    from rwall_fem.scene import load_scene

    sim = build_simulation(load_scene(scene_file, overrides), comm, out)
    if resume:
        sim.checkpoints.resume(sim)
    if comm.rank == 0 and not quiet and sys.stderr.isatty():
        from rwall_fem.output.progress import Progress

        sim.recorders.append(Progress(sim.num_steps))
    sim.run()
    return sim.history.summary


def _check(scene_file, overrides, comm) -> int:
    """Build everything a run needs (mesh, mass, stiffness, stable step, effects) and print
    it, with the wall time estimated from the cost of the internal force."""
    from mpi4py import MPI

    from rwall_fem.build import build_simulation
    from rwall_fem.scene import load_scene

    scene = load_scene(scene_file, overrides)
    sim = build_simulation(scene, comm, out=None)
    started = time.perf_counter()
    for _ in range(5):
        sim.internal.accelerate(sim.state)
    per_step = comm.allreduce(time.perf_counter() - started, op=MPI.MAX) / 5
    info = sim.info
    walls = [comm.allreduce(len(w.nodes)) for w in sim.walls]
    boundaries = [comm.allreduce(len(b.nodes)) for b in sim.boundaries]
    if comm.rank == 0:
        print(f"rwall-fem: scene {scene_file} is valid")
        print(
            f"  body: {info['cells']} {info['cell']} cells, {info['nodes']} nodes, "
            f"{info['mass']:.6g} kg, on {comm.size} rank(s)"
        )
        print(
            f"  time step: {sim.state.dt:.4g} s (stable {info['dt_stable']:.4g} s; "
            f"shortest edge / c_p {info['dt_element_estimate']:.4g} s); "
            f"{sim.num_steps} steps to {sim.num_steps * sim.state.dt:.4g} s"
        )
        print(f"  effects: {', '.join(sim.effects)}")
        for w, count in zip(sim.walls, walls, strict=True):
            print(f"  {w.name}: {w.shape.kind}, slide {w.slide}, {count} secondary nodes")
        for b, count in zip(sim.boundaries, boundaries, strict=True):
            print(f"  {b.name}: {count} nodes, components {''.join('xyz'[i] for i in b.axes)}")
        print(
            f"  estimated wall time: {1.2 * per_step * (sim.num_steps + 1):.3g} s "
            f"(internal force {per_step * 1e3:.3g} ms per step, + 20 % for the rest)"
        )
    return 0


def _render(directory: str, color: str) -> int:
    from pathlib import Path

    from rwall_fem.output.render import render_frames

    if not (Path(directory) / "frames" / "data" / "mesh.npz").is_file():
        print(
            f"rwall-fem: error: {directory}: no frame data (run with output.frames > 0)",
            file=sys.stderr,
        )
        return 2
    files = render_frames(directory, color)
    print(f"rwall-fem: {len(files)} frames and animation.gif in {directory}")
    return 0
