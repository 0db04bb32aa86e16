"""Time histories: ``energy.csv``, ``walls.csv`` and ``summary.json``.

Energies are booked so that, for central differences, the balance closes
exactly (see ``../shared/notes/numerics.md``):

- kinetic energy is the shadow value K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2};
- strain energy is U^n = 1/2 u^n . K u^n;
- the work of every other force g (walls, body forces) is booked at mid-step
  velocities, 1/2 g^n . (v^{n-1/2} + v^{n+1/2}) dt;
- the balance error is (K + U - W_ext - W_wall - E0) / E_ref with E0 the
  initial energy 1/2 sum m v0^2 and E_ref = max(E0, the largest K + U so far).

Every row is flushed as it is written, so a run that stops leaves complete
lines up to its last sample. Rank 0 writes; all ranks take part in the sums.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from mpi4py import MPI

__all__ = ["History"]


class History:
    """Samples energies and wall forces every ``every`` steps and writes the run summary."""

    def __init__(
        self, directory: Path, every: int, num_steps: int, comm: MPI.Comm, info: dict, walls, state
    ):
        self.every, self.num_steps = every, num_steps
        self.comm, self.info, self.walls = comm, info, walls
        self.directory = Path(directory)
        m = state.mass[:, None]
        self.initial_momentum = comm.allreduce(np.sum(m * state.v, axis=0))
        self.initial_energy = comm.allreduce(0.5 * float(np.sum(m * state.v**2)))
        self.reference_energy = self.initial_energy
        self.max_balance_error = 0.0
        self._last_impulse = np.zeros((len(walls), 3))
        self._last_step = -1
        self.energy_rows = []  # (t, K, U, W_ext, W_wall, error), as in energy.csv
        self.wall_rows = []  # (t, wall, F_x, F_y, F_z, I_x, I_y, I_z, contacts), as in walls.csv
        self._energy = self._walls = None
        if comm.rank == 0:
            self.directory.mkdir(parents=True, exist_ok=True)
            self._energy = open(self.directory / "energy.csv", "w")
            self._energy.write("time,kinetic,internal,external_work,wall_work,balance_error\n")
            self._energy.flush()
            if walls:
                self._walls = open(self.directory / "walls.csv", "w")
                self._walls.write(
                    "time,wall,force_x,force_y,force_z,impulse_x,impulse_y,impulse_z,contacts\n"
                )
                self._walls.flush()

    def due(self, step: int) -> bool:
        return step % self.every == 0 or step == self.num_steps

    def record(self, sim, s) -> None:
        """Sample step ``s.step``: needs ``v^{n-1/2}`` and ``a^n`` (before the update)."""
        kinetic = 0.5 * float(np.sum(s.mass[:, None] * s.v * (s.v + s.dt * s.a)))
        local = [kinetic, sim.internal.strain_energy(s)]
        local.append(sum(f.work for f in sim.forces))
        local.append(sum(w.work for w in self.walls))
        for w in self.walls:
            local += [*w.impulse, w.contacts]
        total = self.comm.allreduce(np.array(local))
        kinetic, internal, external, wall_work = total[:4]
        self.reference_energy = max(self.reference_energy, kinetic + internal)
        error = (kinetic + internal - external - wall_work - self.initial_energy) / max(
            self.reference_energy, np.finfo(float).tiny
        )
        self.max_balance_error = max(self.max_balance_error, abs(error))
        row = (s.t, kinetic, internal, external, wall_work, error)
        self.energy_rows.append(row)
        interval = (s.step - self._last_step) * s.dt
        self._last_step = s.step
        rows = []
        for i, chunk in enumerate(total[4:].reshape(-1, 4)):
            impulse, contacts = chunk[:3], int(chunk[3])
            force = (impulse - self._last_impulse[i]) / interval
            self._last_impulse[i] = impulse
            rows.append((s.t, i, *force, *impulse, contacts))
        self.wall_rows += rows
        if self.comm.rank != 0:
            return
        self._energy.write(",".join(f"{x:.17g}" for x in row) + "\n")
        self._energy.flush()
        if rows:
            self._walls.writelines(",".join(f"{x:.17g}" for x in r) + "\n" for r in rows)
            self._walls.flush()

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
        for w in self.walls:
            walls.append(
                {
                    "name": w.name,
                    "kind": w.shape.kind,
                    "impulse": comm.allreduce(w.impulse).tolist(),
                    "work": comm.allreduce(w.work),
                    "first_contact": _finite_or_none(comm.allreduce(w.first_contact, MPI.MIN)),
                    "last_contact": _finite_or_none(comm.allreduce(w.last_contact, MPI.MAX)),
                }
            )
        t, kinetic, internal, external, wall_work, _ = self.energy_rows[-1]
        summary = self.info | {
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
        }
        self.summary = summary
        if comm.rank == 0:
            (self.directory / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
            self._energy.close()
            if self._walls:
                self._walls.close()


def _finite_or_none(x: float):
    return float(x) if np.isfinite(x) else None
