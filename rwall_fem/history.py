"""Time histories: ``energy.csv``, ``walls.csv`` and ``summary.json``.

Energies are booked so that, for central differences, the balance closes
exactly (see ``../shared/notes/numerics.md``):

- kinetic energy is the shadow value K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2},
  walls carried by a main node included;
- strain energy is U^n = 1/2 u^n . K u^n;
- the work of every other force g (body forces, walls) is booked at mid-step
  velocities, 1/2 g^n . (v^{n-1/2} + v^{n+1/2}) dt; the wall work is that of
  the contact impulses relative to the wall (normal stop and friction), the
  driving work of prescribed walls and the reactions of velocity boundary
  conditions count as external work;
- the balance error is (K + U - W_ext - W_wall - E0) / E_ref with E0 the
  initial energy (kinetic, walls included) and E_ref the largest of E0, K + U,
  |W_ext| and |W_wall| so far (a body dropped from rest starts with E0 = 0).

Rows are written in whole lines and flushed at least every ``FLUSH_SECONDS``
of wall time and when the run ends or stops, so a killed run leaves complete
lines up to its last flush. Rank 0 writes; all ranks take part in one sum per
sample.

The guards act at every sample, on the summed values, so every rank takes the
same decision at the same step: non-finite energies (a NaN or Inf in a nodal
array), a balance error above ``max_energy_error``, a step below ``min_dt``,
or a SIGTERM received by any rank stop the run (:class:`RunStopped`) with one
message naming the step, the time, the quantity and the worst node.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem.solver import RunStopped

__all__ = ["History"]

WALL_COLUMNS = (
    ["time", "wall"]
    + [f"force_{c}" for c in "xyz"]
    + [f"impulse_{c}" for c in "xyz"]
    + [f"normal_force_{c}" for c in "xyz"]
    + [f"tangential_force_{c}" for c in "xyz"]
    + [f"normal_impulse_{c}" for c in "xyz"]
    + [f"tangential_impulse_{c}" for c in "xyz"]
    + ["contacts"]
    + [f"position_{c}" for c in "xyz"]
    + [f"velocity_{c}" for c in "xyz"]
)
_PER_WALL = 9  # reduced per wall: normal, tangential impulse (3 + 3), contacts, works (2)
FLUSH_SECONDS = 1.0  # longest wall time between writes of the CSV files, s


class History:
    """Samples energies and wall forces at the steps it is due and writes the run summary."""

    def __init__(
        self,
        directory: Path,
        every: int,
        num_steps: int,
        comm: MPI.Comm,
        info: dict,
        walls,
        state,
        *,
        node_ids: np.ndarray,
        max_energy_error: float = 0.05,
        min_dt: float = 0.0,
        plot: bool = False,
        boundaries=(),
    ):
        self.plot = plot  # draw histories.png at the end
        self.every, self.num_steps = every, num_steps
        self.node_ids = node_ids  # global index of each owned node, for messages
        self.max_energy_error, self.min_dt = max_energy_error, min_dt
        self.comm, self.info, self.walls = comm, info, walls
        self.boundaries = boundaries  # velocity boundary conditions: their reactions' work
        self.directory = Path(directory)
        m = state.mass[:, None]
        moving = [w.motion for w in walls if w.motion.dynamic]
        self.initial_momentum = comm.allreduce(np.sum(m * state.v, axis=0)) + sum(
            (mo.mass * mo.velocity for mo in moving), np.zeros(3)
        )
        self.initial_energy = comm.allreduce(0.5 * float(np.sum(m * state.v**2))) + sum(
            0.5 * mo.mass * mo.velocity @ mo.velocity for mo in moving
        )
        self.reference_energy = self.initial_energy
        self.max_balance_error = 0.0
        self.peak_contacts = np.zeros(len(walls), dtype=int)
        self._last_impulse = np.zeros((len(walls), 6))
        self._last_step = -1
        self.energy_rows = []  # (t, K, U, W_ext, W_wall, error), as in energy.csv
        self.wall_rows = []  # rows of walls.csv
        self._energy = self._walls = None
        self._unwritten = [0, 0]  # rows of energy_rows, wall_rows not yet in the files
        self._written_at = time.monotonic()
        self._local = np.zeros(4 + _PER_WALL * len(walls))  # what each sample reduces
        self._total = np.zeros_like(self._local)
        self._scratch = np.zeros_like(state.v)

    def _open(self) -> None:
        """Create the directory and the CSV files (rank 0) when the run starts writing."""
        self.directory.mkdir(parents=True, exist_ok=True)
        self._energy = open(self.directory / "energy.csv", "w")
        self._energy.write("time,kinetic,internal,external_work,wall_work,balance_error\n")
        if self.walls:
            self._walls = open(self.directory / "walls.csv", "w")
            self._walls.write(",".join(WALL_COLUMNS) + "\n")

    def due(self, step: int) -> bool:
        return step % self.every == 0 or step == self.num_steps

    def record(self, sim, s) -> None:
        """Sample step ``s.step``: needs ``v^{n-1/2}`` and ``a^n`` (before the update)."""
        ahead = np.multiply(s.a, s.dt, out=self._scratch)
        ahead += s.v  # v^{n+1/2}
        local = self._local
        local[0] = 0.5 * np.einsum("i,ij,ij->", s.mass, s.v, ahead)
        local[1] = sim.internal.strain_energy(s)
        local[2] = (
            sum(f.work(s) for f in sim.forces)
            + sum(w.driving_work for w in self.walls)
            + sum(b.work for b in self.boundaries)
        )
        local[3] = float(sim.terminate_requested)
        for w, chunk in zip(self.walls, local[4:].reshape(-1, _PER_WALL), strict=True):
            chunk[:3], chunk[3:6], chunk[6] = w.normal_impulse, w.tangential_impulse, w.contacts
            chunk[7:] = w.normal_work, w.friction_work
        total = self._total
        self.comm.Allreduce(local, total)
        kinetic, internal, external, terminate = map(float, total[:4])
        per_wall = total[4:].reshape(-1, _PER_WALL)
        wall_work = float(per_wall[:, 7:9].sum())
        for w in self.walls:
            if w.motion.dynamic:  # the same on every rank: not part of the sum
                kinetic += 0.5 * w.motion.mass * w.motion.previous_velocity @ w.motion.velocity
        self.reference_energy = max(
            self.reference_energy, kinetic + internal, abs(external), abs(wall_work)
        )
        error = (kinetic + internal - external - wall_work - self.initial_energy) / max(
            self.reference_energy, np.finfo(float).tiny
        )
        self.max_balance_error = max(self.max_balance_error, abs(error))
        row = (s.t, kinetic, internal, external, wall_work, error)
        self.energy_rows.append(row)
        interval = (s.step - self._last_step) * s.dt
        self._last_step = s.step
        rows = []
        for i, (w, chunk) in enumerate(zip(self.walls, per_wall, strict=True)):
            impulses, contacts = chunk[:6].copy(), int(chunk[6])
            self.peak_contacts[i] = max(self.peak_contacts[i], contacts)
            forces = (impulses - self._last_impulse[i]) / interval
            self._last_impulse[i] = impulses
            total_force, total_impulse = forces[:3] + forces[3:], impulses[:3] + impulses[3:]
            rows.append(
                (s.t, i, *total_force, *total_impulse, *forces, *impulses, contacts,
                 *w.position, *w.motion.velocity)
            )  # fmt: skip
        self.wall_rows += rows
        if time.monotonic() - self._written_at > FLUSH_SECONDS:
            self._write()
        self._guard(s, error, terminate, np.isfinite(total).all())

    def _write(self) -> None:
        """Append the rows not yet written, as whole lines, and flush (rank 0)."""
        self._written_at = time.monotonic()
        if self.comm.rank != 0:
            return
        if self._energy is None:
            self._open()
        start, start_walls = self._unwritten
        self._unwritten = [len(self.energy_rows), len(self.wall_rows)]
        self._energy.write("".join(_line(r) for r in self.energy_rows[start:]))
        self._energy.flush()
        if self._walls:
            self._walls.write("".join(_line(r) for r in self.wall_rows[start_walls:]))
            self._walls.flush()

    def _guard(self, s, error: float, terminate: float, finite: bool) -> None:
        """Stop the run (on every rank alike) when a guard trips at this sample."""
        where = f"step {s.step}, t = {s.t:.6g} s"
        if not finite:
            bad = ~(np.isfinite(s.u).all(axis=1) & np.isfinite(s.v).all(axis=1))
            node = self._worst(bad.astype(float), s)
            raise RunStopped(f"{where}: NaN or Inf in the nodal state; first bad node {node}")
        if abs(error) > self.max_energy_error:
            node = self._worst(np.linalg.norm(s.v, axis=1), s, "|v| = {:.4g} m/s")
            raise RunStopped(
                f"{where}: energy balance error {error:.3g} exceeds run.max_energy_error = "
                f"{self.max_energy_error:g}; fastest node {node}"
            )
        if s.dt < self.min_dt:
            raise RunStopped(
                f"{where}: time step {s.dt:.4g} s is below run.min_dt = {self.min_dt:g} s"
            )
        if terminate:
            raise RunStopped(f"{where}: terminated by SIGTERM")

    def _worst(self, score: np.ndarray, s, detail: str = "") -> str:
        """'<global id> at (x, y, z) m' of the node with the largest ``score`` on any rank."""
        score = np.where(np.isnan(score), np.inf, score)
        i = int(np.argmax(score)) if len(score) else -1
        mine = (score[i], self.node_ids[i], *(s.X[i] + s.u[i])) if i >= 0 else (-np.inf,)
        best = max(self.comm.allgather(mine), key=lambda c: c[0])
        text = f"{best[1]} at ({best[2]:.6g}, {best[3]:.6g}, {best[4]:.6g}) m"
        return f"{text}, {detail.format(best[0])}" if detail else text

    @property
    def energy(self) -> np.ndarray:
        """Energy samples as an array with the columns of ``energy.csv``."""
        return np.array(self.energy_rows)

    def wall(self, i: int) -> np.ndarray:
        """Samples of wall ``i`` as an array with the columns of ``walls.csv``."""
        return np.array([r for r in self.wall_rows if r[1] == i])

    def close(self, sim) -> None:
        """Write ``summary.json`` (rank 0) and close the CSV files."""
        s, comm = sim.state, self.comm
        final_momentum = comm.allreduce(np.sum(s.mass[:, None] * s.v, axis=0))
        walls = []
        for i, w in enumerate(self.walls):
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
                "peak_contacts": int(self.peak_contacts[i]),
            }
            if w.motion.dynamic or w.motion.prescribed:
                entry["motion"] = "main node" if w.motion.dynamic else "prescribed"
                entry["position"] = w.position.tolist()
                entry["velocity"] = w.motion.velocity.tolist()
                entry["driving_work"] = comm.allreduce(w.driving_work)
            if w.motion.dynamic:
                entry["mass"] = w.motion.mass
                final_momentum = final_momentum + w.motion.mass * w.motion.velocity
            walls.append(entry)
        t, kinetic, internal, external, wall_work, _ = self.energy_rows[-1]
        summary = self.info | {
            "status": "done" if sim.status == "done" else "stopped",
            "reason": sim.status.removeprefix("stopped: ") if sim.status != "done" else None,
            "ranks": comm.size,
            "steps": sim.num_steps,
            "dt": s.dt,
            "end_time": sim.num_steps * s.dt,
            "wall_seconds": comm.allreduce(sim.wall_seconds, MPI.MAX),
            "effects": sim.effects,
            "initial_momentum": self.initial_momentum.tolist(),
            "final_momentum": final_momentum.tolist(),
            "energy": {
                "initial": self.initial_energy,
                "kinetic": kinetic,
                "internal": internal,
                "external_work": external,
                "wall_work": wall_work,
                "max_balance_error": self.max_balance_error,
            },
            "walls": walls,
            "boundaries": [
                {
                    "name": b.name,
                    "nodes": comm.allreduce(len(b.nodes)),
                    "reaction_impulse": comm.allreduce(b.impulse).tolist(),
                    "work": comm.allreduce(b.work),
                }
                for b in self.boundaries
            ],
        }
        self.summary = summary
        self._write()
        if comm.rank == 0:
            (self.directory / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
            self._energy.close()
            if self._walls:
                self._walls.close()
            if self.plot:
                from rwall_fem.plots import plot_histories

                plot_histories(self.directory)


def _line(row) -> str:
    """A CSV line of the numbers in ``row``: integers as such, floats as their shortest
    exact decimal."""
    return ",".join(repr(x) if isinstance(x, int) else repr(float(x)) for x in row) + "\n"


def _finite_or_none(x: float):
    return float(x) if np.isfinite(x) else None
