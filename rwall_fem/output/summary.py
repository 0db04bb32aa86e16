"""``summary.json``: what ran, how it ended, and the totals of every effect (SI units).

Every value is summed (or reduced) over ranks, so the summary is the same on every
rank; rank 0 writes it. Besides what was built (``Simulation.info``: the code's
``version`` and ``git_hash``, mesh, stable steps, ``warnings``), it holds the outcome
(``status``: done, stopped or failed, and its ``reason``), ``steps`` done (the step of the
last state; ``planned_steps``: as many as the step at the start would take), the ``time``
reached (s) and ``end_time``, ``dt`` (the last step, s) and ``time_step``: the step's
mode, calibration, first, smallest and largest steps (s), where and when the smallest
was, and with mass scaling the mass added (kg and %) and its work (J),
the energies of the last sample, when cells can erode how many did and the nodes they
left detached (``erosion``), for a body of ``[[part]]`` each part's (``parts``: its
material, cells, mass, momentum, energies, largest plastic strain and deformed bounds),
and per wall its impulses, works, contacts and the secondary nodes that started behind
it (``initially_penetrated``, ``deepest_penetration`` in m: kept there by the wall, as
Radioss's starter warns).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem import interrupts
from rwall_fem.output import OutputError

__all__ = [
    "deformed_bounds",
    "momentum",
    "reserve_summary",
    "run_summary",
    "truthful_when_interrupted",
    "write_summary",
]


def momentum(state, walls, comm, rigid=()) -> np.ndarray:
    """Momentum (kg m/s) of the body plus that of the walls carried by a main node; the
    nodes of ``rigid`` bodies count as their bodies, M V."""
    local = np.sum(state.mass[:, None] * state.v, axis=0)
    for r in rigid:
        local = local - r.nodal_momentum(state)
    total = comm.allreduce(local) + sum(r.momentum for r in rigid)
    for w in walls:
        if w.motion.dynamic:
            total = total + w.motion.mass * w.motion.velocity
    return total


def run_summary(sim, balance, peak_contacts, initial_momentum: np.ndarray) -> dict:
    """The summary of the run ``sim`` with the energy ``balance`` (an
    :class:`~rwall_fem.output.energy.EnergyBalance`), the most nodes each wall treated in
    one step and the momentum at the start (kg m/s)."""
    s, comm = sim.state, sim.comm
    outcome, _, reason = sim.status.partition(": ")
    latest = balance.latest or {}
    energy = {"initial": balance.initial}
    energy |= {name: latest.get(name) for name in (*balance.stored, *balance.parts, *balance.works)}
    energy["max_balance_error"] = balance.max_error
    return sim.info | {
        "status": outcome,
        "reason": reason or None,
        "ranks": comm.size,
        "steps": s.step,
        "planned_steps": sim.planned_steps,
        "dt": s.dt,
        "time": s.t,
        "end_time": sim.end_time,
        "time_step": {"mode": getattr(sim.step_size, "mode", "fixed")} | sim.step_size.summary(),
        "wall_seconds": comm.allreduce(sim.wall_seconds, MPI.MAX),
        "effects": sim.effects,
        "initial_momentum": initial_momentum.tolist(),
        "final_momentum": momentum(s, sim.walls, comm, sim.rigid_bodies).tolist(),
        "energy": energy,
        "deformed_bounds": deformed_bounds(s, comm),
        **_plasticity(sim.internal, comm),
        **_erosion(sim.internal, comm),
        **_parts(sim, latest, comm),
        "walls": [_wall(w, peak, comm) for w, peak in zip(sim.walls, peak_contacts, strict=True)],
        "rigid_bodies": [_rigid_body(r, comm) for r in sim.rigid_bodies],
        **({"contacts": [c.summary() for c in sim.contacts]} if sim.contacts else {}),
        "boundaries": [
            {
                "name": b.name,
                "nodes": comm.allreduce(len(b.nodes)),
                "reaction_impulse": comm.allreduce(b.impulse).tolist(),
                "work": comm.allreduce(b.work),
            }
            for b in sim.boundaries
        ],
    }


def _rigid_body(body, comm) -> dict:
    """A rigid body's nodes, mass (kg), inertia about its centre (kg m^2, global frame), and
    its centre (m), velocity (m/s), angular velocity (rad/s) and momenta at the end."""
    return {
        "name": body.name,
        "nodes": comm.allreduce(len(body.nodes)),
        "mass": body.mass,
        "inertia": body.spatial_inertia().tolist(),
        "center": body.center.tolist(),
        "velocity": body.velocity.tolist(),
        "angular_velocity": body.omega.tolist(),
        "momentum": body.momentum.tolist(),
        "angular_momentum": body.angular_momentum.tolist(),
    }


def deformed_bounds(state, comm) -> list[list[float]]:
    """[min corner], [max corner] (m) of the body at the time of the latest step, read
    after its update (u^{n+1} - dt v^{n+1/2} = u^n)."""
    x = state.X + state.u - state.dt * state.v
    low, high = np.empty(3), np.empty(3)
    # Buffers, not pickled objects: mpi4py 3 reduces pickled arrays with Python's min.
    comm.Allreduce(x.min(axis=0, initial=np.inf), low, op=MPI.MIN)
    comm.Allreduce(x.max(axis=0, initial=-np.inf), high, op=MPI.MAX)
    return [low.tolist(), high.tolist()]


def _plasticity(internal, comm) -> dict:
    """The plastic work (J) and the largest equivalent plastic strain of an elasto-plastic
    body; nothing for an elastic one."""
    if not getattr(internal, "plastic", False):
        return {}
    fields = internal.plastic_strains()
    return {
        "plastic_work": comm.allreduce(internal.plastic_work),
        "max_plastic_strain": comm.allreduce(float(fields.max(initial=0.0)), MPI.MAX),
    }


def _erosion(internal, comm) -> dict:
    """How many cells eroded and how many nodes they left detached, and with a failure
    criterion the largest damage of a live cell; nothing when no cell can erode."""
    erosion = getattr(internal, "erosion", None)
    if erosion is None:
        return {}
    entry = {
        "eroded_cells": comm.allreduce(erosion.count),
        "detached_nodes": comm.allreduce(len(erosion.detached)),
    }
    damage = erosion.largest_damage()
    if damage is not None:
        entry["max_damage"] = comm.allreduce(damage, MPI.MAX)
    return {"erosion": entry}


def _parts(sim, latest: dict, comm) -> dict:
    """``parts``: for a body of ``[[part]]``, each part's material, cells, mass (kg),
    momentum (kg m/s), energies of the last sample (J), largest plastic strain and the
    bounds (m) of its nodes at the latest step; nothing for a body of one part."""
    body = sim.internal
    if not getattr(body, "explicit", False):
        return {}
    s = sim.state
    momenta = comm.allreduce(body.part_momenta(s))
    owned = len(s.mass)
    x = s.X + s.u - s.dt * s.v  # u^n: as deformed_bounds
    entries = []
    for k, (part, force) in enumerate(zip(body.parts, body.elements, strict=True)):
        held = body.held[:owned, k] > 0
        low, high = np.empty(3), np.empty(3)
        comm.Allreduce(x[held].min(axis=0, initial=np.inf), low, op=MPI.MIN)
        comm.Allreduce(x[held].max(axis=0, initial=-np.inf), high, op=MPI.MAX)
        prefix = f"{part.name}."
        entry = {
            "name": part.name,
            "material": part.material.model,
            "cells": comm.allreduce(len(part.cells)),
            "mass": comm.allreduce(float(body.part_masses[:, k].sum())),
            "momentum": momenta[k].tolist(),
            "energy": {
                name.removeprefix(prefix): value
                for name, value in latest.items()
                if name.startswith(prefix)
            },
        }
        if force.plastic:
            strain = float(force.plastic_strains().max(initial=0.0))
            entry["max_plastic_strain"] = comm.allreduce(strain, MPI.MAX)
        entries.append(entry | {"deformed_bounds": [low.tolist(), high.tolist()]})
    return {"parts": entries}


def _wall(w, peak_contacts: int, comm) -> dict:
    entry = {
        "name": w.name,
        "kind": w.shape.kind,
        "slide": w.slide,
        "secondary_nodes": comm.allreduce(len(w.nodes)),
        "impulse": comm.allreduce(w.impulse).tolist(),
        "normal_impulse": comm.allreduce(w.normal_impulse).tolist(),
        "tangential_impulse": comm.allreduce(w.tangential_impulse).tolist(),
        "work": comm.allreduce(w.work),
        "normal_work": comm.allreduce(w.normal_work),
        "friction_work": comm.allreduce(w.friction_work),
        "first_contact": _finite_or_none(comm.allreduce(w.first_contact, MPI.MIN)),
        "last_contact": _finite_or_none(comm.allreduce(w.last_contact, MPI.MAX)),
        "peak_contacts": int(peak_contacts),
        "initially_penetrated": w.initially_penetrated,
        "deepest_penetration": w.deepest_penetration,
    }
    if w.motion.dynamic or w.motion.prescribed:
        entry["motion"] = "main node" if w.motion.dynamic else "prescribed"
        entry["position"] = w.position.tolist()
        entry["velocity"] = w.motion.velocity.tolist()
        entry["driving_work"] = comm.allreduce(w.driving_work)
    if w.motion.dynamic:
        entry["mass"] = w.motion.mass
    return entry


def write_summary(directory: Path, summary: dict) -> None:
    """Write ``summary`` to ``directory/summary.json``, whole or not at all (a new file
    renamed over the old), as strict JSON: a value that is NaN or Inf is written null,
    and the key ``non_finite`` lists where (``energy.kinetic``, ``final_momentum[2]``).
    When the new file cannot be written (a full disk), the summary is written in place
    into the room :func:`reserve_summary` kept at the start of the run, if it fits.
    Raises :class:`~rwall_fem.output.OutputError` naming the file."""
    path = Path(directory) / "summary.json"
    text = _json_text(summary)
    partial = path.with_name(".summary.json.partial")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _write_new(partial, text)
        os.replace(partial, path)
    except OSError as err:
        with contextlib.suppress(OSError):
            partial.unlink(missing_ok=True)
        if not _overwrite_in_place(path, text):
            raise OutputError(f"{path}: cannot be written ({err.strerror})") from None
    except BaseException:  # a stop signal: no half-written file is left
        partial.unlink(missing_ok=True)
        raise


def reserve_summary(directory: Path, summary: dict) -> None:
    """Write the summary of a run that starts (``status`` "running") to
    ``directory/summary.json``, followed by blanks up to twice its size and 16 kB more
    (still valid JSON), synced to disk: the room the final summary takes if the disk is
    full by then (:func:`write_summary`). Raises :class:`~rwall_fem.output.OutputError`
    naming the file."""
    path = Path(directory) / "summary.json"
    text = _json_text(summary)
    room = 2 * len(text.encode()) + RESERVE_BYTES
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "wb") as file:
            file.write(text.encode().ljust(room, b" "))
            file.flush()
            os.fsync(file.fileno())
    except OSError as err:
        raise OutputError(f"{path}: cannot be written ({err.strerror})") from None


RESERVE_BYTES = 16384  # room kept in summary.json beyond twice the start's summary, bytes


def _json_text(summary: dict) -> str:
    lost: list[str] = []
    clean = _strict(summary, "", lost)
    if lost:
        clean["non_finite"] = lost
    return json.dumps(clean, indent=2, allow_nan=False) + "\n"


def _write_new(path: Path, text: str) -> None:
    """Write ``text`` into a new file (what a full disk refuses)."""
    path.write_text(text)


def _overwrite_in_place(path: Path, text: str) -> bool:
    """Write ``text`` over the start of ``path`` and blank the rest of it, without growing
    it (the blocks are the file's already); False when it does not fit or cannot be
    written."""
    data = text.encode()
    try:
        with open(path, "r+b") as file:
            size = os.fstat(file.fileno()).st_size
            if len(data) > size:
                return False
            file.write(data.ljust(size, b" "))
            file.flush()
            os.fsync(file.fileno())
    except OSError:
        return False
    return True


def _strict(value, path: str, lost: list[str]):
    """``value`` with its non-finite floats replaced by None, their paths added to ``lost``."""
    if isinstance(value, dict):
        return {k: _strict(v, f"{path}.{k}" if path else k, lost) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict(v, f"{path}[{i}]", lost) for i, v in enumerate(value)]
    if isinstance(value, float) and not math.isfinite(value):
        lost.append(path)
        return None
    return value


@contextlib.contextmanager
def truthful_when_interrupted(sim):
    """Hold while ``sim`` runs and its outputs are finished (the history's summary may
    already say "done"): a stop signal (a KeyboardInterrupt) that comes after the time
    loop makes ``summary.json`` say "stopped" and why, and adds that to ``run.log``; the
    interruption's text (its ``reason``) then says so too. So does the end of the process
    by :mod:`rwall_fem.interrupts`' watcher, when the main thread is stuck in C code."""
    rank = sim.comm.rank  # read here: the watcher thread must not call MPI

    def record(reason: str) -> str:
        return _record_interruption(sim, rank, reason)

    with interrupts.on_emergency(record):
        try:
            yield
        except KeyboardInterrupt as stop:
            reason = record(getattr(stop, "reason", interrupts.REASONS["SIGINT"]))
            if isinstance(stop, interrupts.Interrupted):
                stop.reason = reason
            raise


def _record_interruption(sim, rank: int, reason: str) -> str:
    """The reason of a stop signal after the time loop, written into ``summary.json``
    and ``run.log`` (rank 0); before the history's summary exists, ``reason`` as it is."""
    history = sim.history
    summary = dict(history.summary) if history is not None and history.summary else None
    if summary is None:
        return reason
    late = "while the outputs were being finished (pictures and histories.png may be missing)"
    if summary["status"] == "done":
        summary["status"] = "stopped"
        summary["reason"] = f"{reason} after the last step, {late}"
    else:
        summary["reason"] = f"{summary['reason']}; then {reason} {late}"
    history.summary = summary
    if rank == 0:
        with contextlib.suppress(OutputError, OSError):
            write_summary(history.directory, summary)
            with open(Path(history.directory) / "run.log", "a") as log:
                log.write(f"then stopped: {summary['reason']}\n")
    return summary["reason"]


def _finite_or_none(x: float):
    return float(x) if np.isfinite(x) else None
