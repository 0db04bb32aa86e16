"""Checkpoints of a run, and resuming from them (Radioss /RFILE, LS-DYNA d3dump).

A checkpoint holds, per rank, the arrays of every object that carries state from one
step to the next (:attr:`~rwall_fem.solver.Simulation.stateful`, the
:class:`~rwall_fem.solver.Stateful` protocol), taken after the update and the history
of step n; a resumed run restores them and goes on at step n + 1, so that its outputs
are those of a run that was never stopped. Checkpoints are written every
``output.checkpoint_steps`` steps and ``output.checkpoint_seconds`` of wall time, and at
a clean stop (SIGTERM, a guard) after a whole step, unless the state holds NaN or Inf.

On disk, ``DIR/checkpoint/step_NNNNNNNNNN/rank_R.npz``: each rank writes its file into
``DIR/checkpoint/partial``, and once every rank has, rank 0 renames that directory to
its step and only then removes the previous checkpoint. A kill at any moment leaves
the last complete checkpoint in place; the one with the highest step is resumed.

Each file starts with a header (JSON): the code and DOLFINx versions, the rank count,
the step, every scene key but where the outputs go and how often checkpoints are
written (after ``--set`` overrides; the hash of those keys identifies the scene), and a
digest of the rank's nodes (coordinates and masses: the partition). A resume refuses,
in one line naming what differs, a checkpoint of another scene, rank count, body or
version, or none.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import os
import shutil
import time
import zipfile
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem.output import OutputError

__all__ = ["CheckpointError", "Checkpoints", "body_digest", "latest_checkpoint", "scene_keys"]

log = logging.getLogger("rwall_fem")

# Scene keys that a resume may change: they say where outputs go and when checkpoints are.
FREE_KEYS = ("output.directory", "output.checkpoint_steps", "output.checkpoint_seconds")


class CheckpointError(ValueError):
    """A checkpoint that cannot be resumed; the message is one line meant for the user."""


def scene_keys(scene) -> dict[str, str]:
    """Every key of a validated scene by its path (``wall[0].friction``) and the repr of
    its value, but the :data:`FREE_KEYS`."""
    from rwall_fem.scene.keys import keys_of

    flat = {}

    def walk(value, path):
        if dataclasses.is_dataclass(value):
            for name, (f, _) in keys_of(type(value)).items():
                walk(getattr(value, f.name), f"{path}.{name}" if path else name)
        elif isinstance(value, tuple) and value and dataclasses.is_dataclass(value[0]):
            for i, item in enumerate(value):
                walk(item, f"{path}[{i}]")
        elif path not in FREE_KEYS:
            flat[path] = repr(value)

    walk(scene, "")
    return flat


def body_digest(state) -> str:
    """A digest of the rank's owned nodes: reference coordinates and lumped masses."""
    return hashlib.sha256(state.X.tobytes() + state.mass.tobytes()).hexdigest()


class Checkpoints:
    """The checkpoints of a run in ``directory`` (``DIR/checkpoint``).

    ``identity`` is what a resume must find equal: ``{"code": version, "dolfinx":
    version, "scene": scene_keys(...), "body": body_digest(...)}`` (the rank count is
    added). ``steps`` (0: none) and ``seconds`` (0: none; s of wall time, as rank 0
    measures it) space the periodic checkpoints.
    """

    def __init__(self, directory: Path, comm, identity: dict, *, steps=0, seconds=0.0):
        self.directory, self.comm = Path(directory), comm
        scene = json.dumps(identity["scene"], sort_keys=True)
        self.identity = identity | {
            "ranks": comm.size,
            "scene_hash": hashlib.sha256(scene.encode()).hexdigest(),
        }
        self.steps, self.seconds = steps, seconds
        self._saved = -1  # step of the latest checkpoint written or resumed
        self._since = time.monotonic()  # when it was (rank 0's clock)
        self._next_check, self._gap = 0, 1  # the next look at the clock, steps since the last

    def start(self, first_step: int) -> None:
        """A run starts at ``first_step``: a fresh run (0) drops an earlier checkpoint."""
        self._since = time.monotonic()
        if first_step == 0 and self.comm.rank == 0:
            shutil.rmtree(self.directory, ignore_errors=True)

    def due(self, step: int) -> bool:
        """Whether a checkpoint is due after ``step``; the same on every rank: rank 0
        reads its clock at steps it chooses (about 20 times per interval, at most twice
        as far apart as the previous time) and tells the others."""
        if self.steps and step and step % self.steps == 0:
            return True
        if not self.seconds or step < self._next_check:
            return False
        decision = None
        if self.comm.rank == 0:
            elapsed = time.monotonic() - self._since
            rate = (step - max(self._saved, 0) + 1) / max(elapsed, 1e-9)  # steps per second
            gap = max(1, min(int(rate * self.seconds / 20), 2 * self._gap))
            decision = (elapsed >= self.seconds, gap)
        due, self._gap = self.comm.bcast(decision, root=0)
        self._next_check = step + self._gap
        return due

    def save(self, sim) -> None:
        """Write the checkpoint of ``sim`` at its step ``sim.state.step`` (collective);
        a state with NaN or Inf is not written, and keeps the last good checkpoint."""
        s, comm = sim.state, self.comm
        if s.step == self._saved:
            return
        finite = bool(np.isfinite(s.u).all() and np.isfinite(s.v).all())
        if not comm.allreduce(finite, op=MPI.LAND):
            if comm.rank == 0:
                kept = f"step {self._saved}" if self._saved >= 0 else "none"
                log.warning(
                    "no checkpoint at step %d: NaN or Inf in the state (kept: %s)", s.step, kept
                )
            return
        arrays, failure = {}, None
        try:  # a piece flushes its outputs first, which may fail on rank 0 alone
            arrays = {
                f"{name}/{key}": np.asarray(value)
                for name, piece in sim.stateful.items()
                for key, value in piece.checkpoint_state().items()
            }
        except OutputError as err:
            failure = str(err)
        self._agree_outputs(failure)
        header = self.identity | {"step": s.step, "time": s.t, "rank": comm.rank}
        partial = self.directory / "partial"
        mine = partial / f"rank_{comm.rank}.npz"
        self._together(lambda: _empty_directory(partial), partial, rank0=True)
        self._together(lambda: _write(mine, header, arrays), mine)
        final = self.directory / f"step_{s.step:010d}"
        self._together(lambda: _publish(partial, final), final, rank0=True)
        self._saved, self._since = s.step, time.monotonic()

    def resume(self, sim) -> None:
        """Restore ``sim`` from the latest checkpoint (collective); it then runs from the
        step after it. Raises :class:`CheckpointError` (one line, on every rank) when there
        is none, or when it is another scene's, rank count's, body's or version's."""
        comm = self.comm
        latest = latest_checkpoint(self.directory.parent, comm)
        path = Path(latest) / f"rank_{comm.rank}.npz"
        arrays, header, error = None, None, None
        try:
            with np.load(path, allow_pickle=False) as npz:
                arrays = dict(npz)
            header = json.loads(str(arrays.pop("header")))
            error = _header_problem(header)
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as err:
            error = f"cannot be read ({type(err).__name__}: {' '.join(str(err).split())})"
        if error:
            error, header = f"{path}: {error}", None
        ranks = comm.bcast(header["ranks"] if header else None, root=0)
        if ranks is not None and ranks != comm.size:
            raise CheckpointError(
                f"{latest}: written by a run on {ranks} rank(s); this run has {comm.size}: "
                f"resume on {ranks}"
            )
        self._agree(error or self._differences(header, latest))
        for name, piece in sim.stateful.items():
            self._agree(_restore(piece, name, arrays, path))
        if sim.state.step != header["step"]:
            error = f"{path}: its state is of step {sim.state.step}, its header of {header['step']}"
        self._agree(error)
        sim.first_step = header["step"] + 1
        self._saved = header["step"]
        log.info("resuming after step %d (t = %.6g s) from %s", header["step"], sim.state.t, latest)

    def _differences(self, header: dict, where) -> str | None:
        """The first identity field in which ``header`` differs from this run's, in words."""
        mine = self.identity
        if header["code"] != mine["code"]:
            return f"{where}: written by rwall-fem {header['code']}; this is {mine['code']}"
        if header["dolfinx"] != mine["dolfinx"]:
            return f"{where}: written with DOLFINx {header['dolfinx']}; this is {mine['dolfinx']}"
        if header["scene_hash"] != mine["scene_hash"]:
            old, new = header["scene"], mine["scene"]
            path = next(k for k in sorted(old.keys() | new.keys()) if old.get(k) != new.get(k))
            return (
                f"{where}: written for another scene: {path} is {new.get(path, 'not set')}, "
                f"was {old.get(path, 'not set')} (resume with the scene and --set of that run)"
            )
        if header["body"] != mine["body"]:
            return f"{where}: rank {header['rank']} has other nodes (another mesh or partition)"
        return None

    def _agree(self, error: str | None) -> None:
        """Raise the first rank's error, if any rank has one, on every rank."""
        errors = [e for e in self.comm.allgather(error) if e]
        if errors:
            raise CheckpointError(errors[0])

    def _together(self, action, path: Path, rank0: bool = False) -> None:
        """Run ``action`` on ``path`` (on rank 0 only if ``rank0``); an OSError on any rank
        raises :class:`~rwall_fem.output.OutputError`, naming the file, on every rank."""
        error = None
        if not rank0 or self.comm.rank == 0:
            try:
                action()
            except OSError as err:
                error = f"checkpoint: {err.filename or path}: {err.strerror}"
        self._agree_outputs(error)

    def _agree_outputs(self, error: str | None) -> None:
        """Raise the first rank's output error, if any rank has one, on every rank."""
        errors = [e for e in self.comm.allgather(error) if e]
        if errors:
            raise OutputError(errors[0])


# The header of a checkpoint file: its keys and the types of their values.
HEADER = {"code": str, "dolfinx": str, "scene": dict, "scene_hash": str, "body": str,
          "ranks": int, "step": int, "time": float, "rank": int}  # fmt: skip


def _header_problem(header) -> str | None:
    """What makes ``header`` (read from JSON) not that of a checkpoint, or None."""
    if not isinstance(header, dict):
        return f"its header is {type(header).__name__}, not a checkpoint's (an object)"
    for key, kind in HEADER.items():
        value = header.get(key)
        if kind is float and isinstance(value, int):
            value = float(value)
        if not isinstance(value, kind) or isinstance(value, bool):
            return f"its header has no {key} (a {kind.__name__}): not a checkpoint's"
    if header["step"] < 0 or header["ranks"] < 1:
        return f"its header has step {header['step']} on {header['ranks']} rank(s)"
    return None


def _restore(piece, name: str, arrays: dict, path: Path) -> str | None:
    """Give ``piece`` its arrays from the file ``path``; a one-line error naming the file
    if they do not fit. What the piece would write now gives the shapes its arrays must
    have (NumPy would spread an array of the wrong shape over the state without a word);
    an array empty now (the contacts of a wall before its first step) may have any."""
    prefix = f"{name}/"
    mine = {k.removeprefix(prefix): v for k, v in arrays.items() if k.startswith(prefix)}
    for key, now in piece.checkpoint_state().items():
        now = np.asarray(now)
        if key not in mine:
            return f"{path}: {name} has no {key!r} (written by another version of the code)"
        if now.size and mine[key].shape != now.shape:
            return (
                f"{path}: {name}/{key} has the shape {mine[key].shape}; this run's is "
                f"{now.shape} (the file was changed, or is another run's)"
            )
        if now.size and mine[key].dtype.kind not in "biuf":
            return f"{path}: {name}/{key} holds {mine[key].dtype} values, not numbers"
    try:
        piece.restore_state(mine)
    except (KeyError, ValueError, TypeError, IndexError) as err:
        return f"{path}: {name}: {' '.join(str(err).split())}"
    return None


def _empty_directory(path: Path) -> None:
    shutil.rmtree(path, ignore_errors=True)
    path.mkdir(parents=True)


def _write(path: Path, header: dict, arrays: dict) -> None:
    with open(path, "wb") as file:
        np.savez(file, header=np.array(json.dumps(header)), **arrays)
        file.flush()
        os.fsync(file.fileno())


def _publish(partial: Path, final: Path) -> None:
    """Make the complete ``partial`` the checkpoint ``final``, then drop the older ones."""
    partial.rename(final)
    _sync(final.parent)
    for older in final.parent.glob("step_*"):
        if older != final:
            shutil.rmtree(older, ignore_errors=True)


def _sync(directory: Path) -> None:
    """Put a rename in ``directory`` on disk."""
    descriptor = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def latest_checkpoint(results: Path, comm) -> str:
    """The latest complete checkpoint of the results folder ``results`` (every rank);
    :class:`CheckpointError` when there is none, or no such folder."""
    latest = _latest(Path(results) / "checkpoint") if comm.rank == 0 else None
    latest = comm.bcast(latest, root=0)
    if latest is None:
        raise CheckpointError(
            f"{Path(results) / 'checkpoint'}: no checkpoint to resume from (a run writes one "
            "at a stop, and every output.checkpoint_steps or _seconds)"
        )
    return latest


def _latest(directory: Path) -> str | None:
    """The complete checkpoint with the highest step in ``directory``, if any."""
    steps = [p for p in directory.glob("step_*") if p.name[5:].isdigit()]
    return str(max(steps, key=lambda p: int(p.name[5:]))) if steps else None
