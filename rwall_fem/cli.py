"""Command line.

- ``rwall-fem run SCENE [--out DIR] [--set key=value ...] [--quiet] [--resume]``: run a
  scene, or with ``--resume`` continue the run whose checkpoint is in DIR;
- ``rwall-fem check SCENE [--set ...]``: validate it and print what would run;
- ``rwall-fem render DIR [--color ...] [--view ...]``: draw the frames of a results folder
  again, in another colouring or view;
- ``rwall-fem study [--quick] [--shells] [--out DIR]``: what accuracy costs in time
  (:mod:`rwall_fem.study`);
- ``rwall-fem convert NAME_0000.rad DIR [--force]``: a Radioss deck as a scene and its
  mesh (:mod:`rwall_fem.radioss`; a scene of that name in DIR is replaced only with
  ``--force``); ``run`` and ``check`` also take a deck as they take a scene.

Exit codes: 0 done, 2 bad input (one line on stderr, no traceback, on every rank; also a
mistake on the command line, a checkpoint that does not fit the scene, code the C
compiler cannot build), 3 run stopped by a guard, SIGTERM or SIGINT (Ctrl-C) (one line
on stderr; the outputs up to the stop are kept, and a checkpoint of the step), or a
command stopped by one of them at any other stage (:mod:`rwall_fem.interrupts`), 4 an
output could not be written (one line on stderr naming it; the others are written).

Messages: facts on stdout, warnings and errors on stderr, each line starting with
``rwall-fem:``; only rank 0 speaks. ``--quiet`` keeps warnings and errors. While a run
goes, a terminal shows a progress bar; otherwise (a batch job, ``mpirun``) stderr gets a
cycle line at the interval of ``run.log``.
"""

from __future__ import annotations

import argparse
import functools
import logging
import sys
import time

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    from rwall_fem import interrupts

    # First of all: a Ctrl-C while the libraries load is one line too.
    with interrupts.handling() as say:
        try:
            return _command(argv)
        except interrupts.Interrupted as stop:  # outside the time loop (it stops by itself)
            say(stop.reason)
            _leave_the_job()
            return 3


def _command(argv: list[str] | None) -> int:
    from rwall_fem import __version__
    from rwall_fem.output.render import COLORS

    parser = _Parser(
        prog="rwall-fem", description="Solid bodies striking rigid walls (explicit FEM on DOLFINx)."
    )
    parser.add_argument("--version", action="version", version=f"rwall-fem {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="run a scene")
    check = commands.add_parser("check", help="validate a scene and print what would run")
    for sub in (run, check):
        sub.add_argument("scene", help="scene file (TOML), or a Radioss deck NAME_0000.rad")
        sub.add_argument(
            "--set",
            dest="overrides",
            action="append",
            default=[],
            metavar="KEY=VALUE",
            help="override a scene key, value read as TOML (e.g. mesh.element_size=5e-4)",
        )
        sub.add_argument(
            "--lift-limits",
            action="store_true",
            help="run whatever the size (run.max_cells, run.max_steps, run.max_frames)",
        )
    run.add_argument("--out", help="results directory (default: the scene's output.directory)")
    run.add_argument("--quiet", action="store_true", help="print only warnings and errors")
    run.add_argument(
        "--resume",
        action="store_true",
        help="continue the run whose checkpoint is in the results directory (/RFILE)",
    )
    render = commands.add_parser("render", help="draw the frames of a results folder again")
    render.add_argument("directory", help="results folder of a run with output.frames > 0")
    render.add_argument(
        "--color",
        default=COLORS[0],
        help=f"{', '.join(COLORS)}, or a cell field of the body such as plastic_strain",
    )
    render.add_argument(
        "--view",
        help="the keys of [output.view] as a TOML inline table's inside, e.g. "
        "'cut = \"y\", zoom = 1.5' (default: the run's view)",
    )
    convert = commands.add_parser(
        "convert", help="write a Radioss deck as a scene (TOML) and its mesh (gmsh)"
    )
    convert.add_argument("deck", help="the starter file NAME_0000.rad (NAME_0001.rad beside it)")
    convert.add_argument("directory", help="where NAME.toml and NAME.msh go")
    convert.add_argument(
        "--force", action="store_true", help="replace a NAME.toml and NAME.msh in DIRECTORY"
    )
    study = commands.add_parser("study", help="accuracy against wall time, on exact references")
    study.add_argument("--quick", action="store_true", help="coarse levels only (< 2 minutes)")
    study.add_argument("--out", default="results/study", help="results directory")
    study.add_argument("--shells", action="store_true",
                       help="only shells against solids: the struck plate (shells.md)")  # fmt: skip
    args = parser.parse_args(argv)
    if args.command == "render":
        return _render(args.directory, args.color, args.view)

    import numpy as np
    from mpi4py import MPI

    from rwall_fem.checkpoint import CheckpointError
    from rwall_fem.kernels import KernelBuildError
    from rwall_fem.output import OutputError
    from rwall_fem.scene import SceneError

    comm = MPI.COMM_WORLD
    quiet = getattr(args, "quiet", False)
    _set_up_logging(quiet, comm.rank)
    # The arithmetic of a state that went NaN or Inf warns at every operation; the guards
    # stop such a run in one line naming the step and the node, and the summary says null.
    with np.errstate(all="ignore"):
        try:
            if args.command == "study":
                code = _study(args.out, args.quick, comm, args.shells)
            elif args.command == "convert":
                code = _convert(args.deck, args.directory, comm, args.force)
            elif args.command == "check":
                code = _check(args.scene, args.overrides, comm, args.lift_limits)
            else:
                summary = _run(
                    args.scene, args.out, args.overrides, comm, quiet, args.lift_limits,
                    args.resume,
                )  # fmt: skip
                code = 0 if summary["status"] == "done" else 3
        except (SceneError, CheckpointError, KernelBuildError) as err:
            if comm.rank == 0:
                print(f"rwall-fem: error: {err}", file=sys.stderr)
            code = 2
        except (OutputError, OSError) as err:
            if comm.rank == 0:
                print(f"rwall-fem: error: outputs: {err}", file=sys.stderr)
            code = 4
        except Exception:
            if comm.size == 1:
                raise
            # A failure of this rank alone: the others may wait for it in a collective call.
            import traceback

            traceback.print_exc()
            print(f"rwall-fem: error: internal error on rank {comm.rank}", file=sys.stderr)
            comm.Abort(1)
    # Rank 0 draws the pictures alone: the others wait for it here, where a stop signal is
    # still handled, rather than in MPI's finalisation, where SIGTERM would end them and
    # their launcher would kill rank 0 before it could stop its renderer and say why.
    comm.Barrier()
    return code


class _Parser(argparse.ArgumentParser):
    """argparse, with its errors in one line (its usage text is what ``--help`` prints),
    from rank 0 only."""

    def error(self, message: str):
        from rwall_fem.interrupts import rank

        if rank() == 0:
            name = self.prog.removeprefix("rwall-fem").strip()
            where = f"{name}: " if name else ""
            print(
                f"rwall-fem: error: {where}{message} (see {self.prog} --help)",
                file=sys.stderr,
            )
        sys.exit(2)


def _leave_the_job() -> None:
    """After a stop signal outside the time loop, a process of a job of several MPI ranks
    ends at once (:func:`rwall_fem.interrupts.leave`): the others may be anywhere."""
    from rwall_fem import interrupts

    MPI = sys.modules.get("mpi4py.MPI")
    if MPI is not None and MPI.Is_initialized() and MPI.COMM_WORLD.size > 1:
        interrupts.leave(3)


def _set_up_logging(quiet: bool, rank: int) -> None:
    """``rwall_fem``'s logger: facts on stdout (unless ``quiet``), warnings on stderr, rank 0
    only. Below warnings, nothing else reaches the root logger's handlers: the form
    compiler's JIT (FFCx through setuptools) logs its gcc commands there at INFO."""
    root = logging.getLogger()
    root.setLevel(logging.WARNING)
    if not any(isinstance(f, _WarningsOnly) for f in root.filters):
        root.addFilter(_WarningsOnly())
    log = logging.getLogger("rwall_fem")
    for old in list(log.handlers):  # main() may run more than once in a process (tests)
        log.removeHandler(old)
    facts = _Console("stdout")
    facts.setFormatter(logging.Formatter("rwall-fem: %(message)s"))
    facts.addFilter(lambda record: record.levelno < logging.WARNING)
    warnings = _Console("stderr")
    warnings.setLevel(logging.WARNING)
    warnings.setFormatter(logging.Formatter("rwall-fem: warning: %(message)s"))
    log.addHandler(facts)
    log.addHandler(warnings)
    log.propagate = False
    level = logging.WARNING if quiet else logging.INFO
    log.setLevel(level if rank == 0 else logging.CRITICAL + 1)  # only rank 0 speaks


class _Console(logging.StreamHandler):
    """A handler writing to ``sys.<name>`` as it is when a record comes (tests swap it)."""

    def __init__(self, name: str):
        self._stream_name = name
        super().__init__()

    @property
    def stream(self):
        return getattr(sys, self._stream_name)

    @stream.setter
    def stream(self, value):
        """The stream is always the current ``sys.<name>``."""


class _WarningsOnly(logging.Filter):
    """Drops records below WARNING, whatever level the root logger is set to later
    (setuptools sets it to INFO while it compiles)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return record.levelno >= logging.WARNING


def _run(scene_file, out, overrides, comm, quiet: bool, lift_limits: bool, resume: bool) -> dict:
    from pathlib import Path

    from rwall_fem.build import build_simulation, run_in_folder
    from rwall_fem.checkpoint import latest_checkpoint
    from rwall_fem.output.run_log import CycleLines, cycle_schedule

    scene, deck_report = _load(scene_file, overrides, comm)
    if resume:  # before meshing, and before the folder is made
        latest_checkpoint(Path(out) if out is not None else scene.output.directory, comm)
    sim = build_simulation(scene, comm, out, limits=not lift_limits)
    if deck_report is not None:
        deck_report.say()
    if comm.rank == 0 and not quiet:
        if sys.stderr.isatty():
            from rwall_fem.output.progress import Progress

            sim.recorders.append(Progress(scene.run.end_time))
        else:
            schedule = cycle_schedule(scene.run.end_time, scene.output.print_interval)
            sim.recorders.append(CycleLines(sys.stderr, schedule))
    run_in_folder(sim, functools.partial(_say_how_it_ended, quiet=quiet), resume=resume)
    return sim.history.summary


def _load(scene_file, overrides, comm, listing: bool = False):
    """The scene of a TOML file, or of a Radioss deck (:mod:`rwall_fem.radioss`), and
    for a deck its :class:`~rwall_fem.radioss.DeckReport` (None for a TOML file), to say
    once the run is built: a deck whose run cannot be built gets one line, the error."""
    from rwall_fem.radioss import is_deck, load_deck
    from rwall_fem.scene import load_scene

    if is_deck(scene_file):
        report: list = []
        scene = load_deck(scene_file, overrides, comm, report=report, listing=listing)
        return scene, report[0]
    return load_scene(scene_file, overrides), None


def _convert(deck: str, directory: str, comm, force: bool) -> int:
    """``rwall-fem convert``: rank 0 writes the scene and its mesh (not over a scene of
    the same name, unless ``force``); a refusal reaches every rank."""
    from rwall_fem.radioss import DeckError, convert

    outcome = None
    if comm.rank == 0:
        try:
            outcome = str(convert(deck, directory, force=force))
        except DeckError as err:
            outcome = err
    outcome = comm.bcast(outcome, root=0)
    if isinstance(outcome, DeckError):
        raise outcome
    if comm.rank == 0:
        print(f"rwall-fem: wrote {outcome} and its mesh")
    return 0


def _study(out: str, quick: bool, comm, shells: bool = False) -> int:
    """``rwall-fem study [--shells]``: its folder checked first, as a run's is."""
    from pathlib import Path

    from rwall_fem.output.folder import check_folder
    from rwall_fem.study import run_shell_study, run_study

    check_folder(Path(out), "--out", comm)
    (run_shell_study if shells else run_study)(out, quick=quick, comm=comm)
    return 0


def _say_how_it_ended(sim, quiet: bool) -> None:
    """One line from rank 0: stopped (stderr, always) or done (stdout, unless quiet)."""
    summary = sim.history.summary
    if sim.comm.rank != 0:
        return
    if summary["status"] != "done":
        print(f"rwall-fem: stopped: {summary['reason']}", file=sys.stderr, flush=True)
    elif not quiet:
        e = summary["energy"]
        step = summary["time_step"]
        sizes = (
            f"of {step['first']:.4g} s"
            if step["smallest"] == step["largest"]
            else f"of {step['smallest']:.4g} to {step['largest']:.4g} s"
        )
        print(
            f"rwall-fem: done: {summary['steps']} steps {sizes} on "
            f"{summary['ranks']} rank(s) in {summary['wall_seconds']:.2f} s; "
            f"max energy balance error {e['max_balance_error']:.2e}",
            flush=True,
        )


def _check(scene_file, overrides, comm, lift_limits: bool) -> int:
    """Print the size of the run estimated before meshing, then build everything a run
    needs (mesh, mass, stiffness, stable step, effects; refused as ``run`` would) and
    print it, with the wall time estimated from the cost of the internal force."""
    from mpi4py import MPI

    from rwall_fem.build import build_simulation
    from rwall_fem.estimate import estimate

    scene, deck_report = _load(scene_file, overrides, comm, listing=True)
    guess = estimate(scene, comm.size)  # on every rank: it may refuse the scene
    if comm.rank == 0:
        print(f"rwall-fem: estimate before meshing: {guess.describe()}")
    sim = build_simulation(scene, comm, out=None, limits=not lift_limits)
    if deck_report is not None:
        deck_report.say()
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
        adaptive = sim.step_size.mode == "adaptive"
        steps = (
            f"about {sim.planned_steps} steps to {scene.run.end_time:.4g} s if the step stays "
            "at its value at rest (an adaptive step falls as cells are crushed)"
            if adaptive
            else f"{sim.planned_steps} steps to {scene.run.end_time:.4g} s"
        )
        shells = info["cell"] in ("quadrilateral", "triangle")  # no eigenvalue: the L_c / c
        stable = "" if shells else f"{info['dt_stable']:.4g} s from the eigenvalue, "
        print(
            f"  time step: {sim.step_size.mode}, {sim.state.dt:.4g} s at rest (stable "
            f"{stable}{info['dt_element_estimate']:.4g} s from the smallest cell L/c); {steps}"
        )
        print(f"  effects: {', '.join(sim.effects)}")
        cards = deck_report.walls if deck_report is not None else [""] * len(walls)
        for w, count, card in zip(sim.walls, walls, cards, strict=True):
            print(f"  {w.name}{f' {card}' if card else ''}: {w.shape.kind}, slide {w.slide}, "
                  f"{count} secondary nodes")  # fmt: skip
        for b, count in zip(sim.boundaries, boundaries, strict=True):
            print(f"  {b.name}: {count} nodes, components {''.join('xyz'[i] for i in b.axes)}")
        print(
            f"  estimated wall time: {1.2 * per_step * (sim.planned_steps + 1):.3g} s "
            f"(internal force {per_step * 1e3:.3g} ms per step, + 20 % for the rest)"
        )
        for line in deck_report.listing if deck_report is not None else ():
            print(f"  {line}")
    return 0


def _render(directory: str, color: str, view: str | None) -> int:
    from rwall_fem.output.render import main as render

    return render([directory, "--color", color, *(["--view", view] if view is not None else [])])
