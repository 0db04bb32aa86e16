"""Command line: ``rwall-fem run SCENE [--out DIR] [--set key=value ...]``, and
``rwall-fem study [--quick] [--out DIR]`` (what accuracy costs in time, :mod:`rwall_fem.study`).

Exit codes: 0 done, 2 bad input (one line on stderr, no traceback), 3 run stopped by a
guard or by SIGTERM (one line on stderr; the outputs up to the stop are kept).
"""

from __future__ import annotations

import argparse
import logging
import sys


def main(argv: list[str] | None = None) -> int:
    from rwall_fem import __version__

    parser = argparse.ArgumentParser(
        prog="rwall-fem", description="Solid bodies striking rigid walls (explicit FEM on DOLFINx)."
    )
    parser.add_argument("--version", action="version", version=f"rwall-fem {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="run a scene")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", help="results directory (default: the scene's output.directory)")
    run.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a scene key, value read as TOML (e.g. mesh.element_size=5e-4)",
    )
    run.add_argument("--quiet", action="store_true", help="print only errors")
    study = commands.add_parser("study", help="accuracy against wall time, on exact references")
    study.add_argument("--quick", action="store_true", help="coarse levels only (< 2 minutes)")
    study.add_argument("--out", default="results/study", help="results directory")
    args = parser.parse_args(argv)
    if args.command == "study":
        from rwall_fem.study import run_study

        run_study(args.out, quick=args.quick)
        return 0

    from mpi4py import MPI

    from rwall_fem.model import run_scene
    from rwall_fem.scene import SceneError

    comm = MPI.COMM_WORLD
    log = logging.getLogger("rwall_fem")
    handler = logging.StreamHandler(sys.stdout)
    handler.setFormatter(logging.Formatter("rwall-fem: %(message)s"))
    log.addHandler(handler)
    log.propagate = False
    log.setLevel(logging.WARNING if args.quiet or comm.rank != 0 else logging.INFO)
    try:
        summary = run_scene(args.scene, args.out, args.overrides, comm)
    except SceneError as err:
        if comm.rank == 0:
            print(f"rwall-fem: error: {err}", file=sys.stderr)
        return 2
    if summary["status"] != "done":
        if comm.rank == 0:
            print(f"rwall-fem: stopped: {summary['reason']}", file=sys.stderr)
        return 3
    if comm.rank == 0 and not args.quiet:
        e = summary["energy"]
        print(
            f"rwall-fem: done: {summary['steps']} steps of {summary['dt']:.4g} s on "
            f"{summary['ranks']} rank(s) in {summary['wall_seconds']:.2f} s; "
            f"max energy balance error {e['max_balance_error']:.2e}"
        )
    return 0
