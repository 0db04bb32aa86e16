"""The energy balance of a run, booked so that it closes exactly for central differences.

``docs/theory.md`` (section "Energy balance") derives the booking:

- the kinetic energy is the shadow value K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2} (booked by
  the update of step n), walls carried by a main node included; the rigid bodies' nodes
  are not in it: their bodies' kinetic energy is the column ``rigid_body``
  (:mod:`rwall_fem.rigid_body`);
- the stored energies come from the internal force: ``"internal"`` (the strain energy of
  the element kernels: 1/2 u.Ku for linear elasticity, the integral of the energy density
  for the hyperelastic models; for a force without stored energy, its work at mid-step
  velocities), ``"hourglass"`` (one-point hexahedra with hourglass control) and, when
  cells may erode, ``"eroded_internal"`` (what the eroded cells took with them);
- the work of every other force (body forces, walls, boundary conditions) is booked at
  mid-step velocities, 1/2 g^n . (v^{n-1/2} + v^{n+1/2}) dt. The wall work is that of
  the contact impulses relative to the wall (normal stop and friction); the driving work
  of prescribed walls and the reactions of velocity boundary conditions are external;
- the balance error is (sum of the stored energies - W_ext - W_wall - E0) / E_ref with
  E0 the initial kinetic energy (walls included) and E_ref the largest of E0, the stored
  energy and |W| of each work so far (a body dropped from rest starts with E0 = 0).

Each row of ``energy.csv`` also carries what LS-DYNA's GLSTAT and Radioss's energy
report print: the total energy (the sum of the stored energies), the balance error in
percent, and the time step of that step (s); with mass scaling also the mass added so
far (kg and % of the body's), and its work (``mass_scaling_work``: the kinetic energy
the added masses cost when they joined their nodes at rest); when cells may erode, how many
have (``eroded_cells``); for a body of ``[[part]]`` each part's energies as LS-DYNA's
MATSUM prints them (``<part>.kinetic``, ``<part>.internal``, ``<part>.hourglass``,
``<part>.plastic_work``; the body's, walls and eroded energies aside, are their sums).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

__all__ = ["WORKS", "EnergyBalance", "initial_kinetic_energy"]

TINY = float(np.finfo(float).tiny)  # the smallest normal double: E_ref is never below it
# The works a balance may book (J), in the order of their columns: a run books those its
# effects do (:class:`~rwall_fem.output.history.History`).
WORKS = ("external_work", "wall_work", "damping_work", "mass_scaling_work", "step_change_work")


def initial_kinetic_energy(state, walls, comm, rigid=()) -> float:
    """1/2 m v^2 (J) of the body at the start, plus that of walls carried by a main node;
    the nodes of ``rigid`` bodies count as their bodies, 1/2 M V^2 + 1/2 omega . L."""
    nodal = 0.5 * state.mass[:, None] * state.v**2
    body = comm.allreduce(
        float(np.sum(nodal)) - sum(float(np.sum(nodal[r.nodes])) for r in rigid)
    )
    moving = [w.motion for w in walls if w.motion.dynamic]
    walls_energy = sum(0.5 * mo.mass * mo.velocity @ mo.velocity for mo in moving)
    return body + walls_energy + sum(r.initial_kinetic() for r in rigid)


class EnergyBalance:
    """The running balance of energies (J) already summed over ranks.

    ``stored`` names the energies the body holds (kinetic first, then those of the
    internal force), ``works`` the works done on it, ``parts`` parts of a stored energy
    reported beside it (the elastic energy and plastic work within the internal energy of
    an elasto-plastic body), not added again, ``extras`` other columns of the row;
    :attr:`columns` are those of ``energy.csv``: time, stored..., parts..., works...,
    balance error, total energy, error in %, dt, extras....
    """

    def __init__(
        self,
        initial: float,
        stored: Sequence[str] = ("kinetic", "internal"),
        works: Sequence[str] = ("external_work", "wall_work"),
        parts: Sequence[str] = (),
        extras: Sequence[str] = (),
    ):
        self.stored, self.works, self.parts = tuple(stored), tuple(works), tuple(parts)
        self.extras = tuple(extras)
        self.columns = (
            "time", *self.stored, *self.parts, *self.works, "balance_error", "total_energy",
            "energy_error_percent", "dt", *self.extras,
        )  # fmt: skip
        self.initial = initial  # E0, J
        self.reference = initial  # E_ref so far, J
        self.max_error = 0.0  # largest finite |balance error| so far
        self.error: float | None = None  # balance error of the latest sample (None: none yet)
        self._row: tuple | None = None  # the latest sample

    @property
    def latest(self) -> dict[str, float] | None:
        """The latest sample, by column (None before the first)."""
        return None if self._row is None else dict(zip(self.columns, self._row, strict=True))

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """E0, E_ref and the largest error so far, and the latest sample (empty: none)."""
        return {
            "books": np.array([self.initial, self.reference, self.max_error]),
            "latest": np.array(self._row or (), dtype=float),
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.initial, self.reference, self.max_error = arrays["books"].tolist()
        latest = tuple(arrays["latest"].tolist())
        self._row = latest or None
        self.error = self.latest["balance_error"] if latest else None

    def sample(
        self, t: float, energies: Mapping[str, float], dt: float, extras: Mapping | None = None
    ) -> tuple:
        """Book the energies (J, summed over ranks) of time ``t`` (s), whose step is ``dt``
        (s), with the values of the ``extras`` columns; returns the row."""
        stored = sum(energies[name] for name in self.stored)
        self.reference = max(self.reference, stored, *(abs(energies[name]) for name in self.works))
        balance = stored
        for name in self.works:
            balance -= energies[name]
        error = (balance - self.initial) / max(self.reference, TINY)
        if math.isfinite(error):  # a NaN or Inf step says nothing of the balance before it
            self.max_error = max(self.max_error, abs(error))
        row = (
            t, *(energies[name] for name in (*self.stored, *self.parts, *self.works)), error,
            stored, 100.0 * error, dt, *((extras or {})[name] for name in self.extras),
        )  # fmt: skip
        self.error, self._row = error, row
        return row
