"""A body of shells: its parts' element forces and moments, and its nodes' rotations.

Each node has six degrees of freedom: the three translations of the body's
:class:`~rwall_fem.solver.State` (walls, boundary conditions, gravity and the update act
on them as on a solid's nodes), and three rotations, whose angular velocity ``w`` (rad/s,
global axes) lives here, in a second P1 vector field on the same space. The elements take
their frame from the current coordinates and their strain rates from ``v`` and ``w``
(rate form), so the angular velocity is all of a node's rotations that a step needs: they
are never summed into a rotation vector.

:class:`ShellBody` is the internal force of the step pipeline: its :meth:`accelerate` sets
``state.a = -f / m`` and the angular acceleration ``alpha = -M / I`` (kg, kg m^2:
:mod:`rwall_fem.shells.inertia`); :class:`~rwall_fem.shells.update.ShellUpdate` advances
``w`` with ``v`` and books the rotations' kinetic energy and the work of the moments.
Its energies are those of a force without a stored energy: the work of the forces and
moments at mid-step velocities (the internal energy: that work less the hourglass
energy the kernels report), and the rotations' shadow kinetic energy
``"rotational_kinetic"`` (``docs/theory.md``, "Shell bodies").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.elements import GhostedField
from rwall_fem.body import PartedBody, held_nodes
from rwall_fem.erosion import ErodedParts
from rwall_fem.internal_force import acceleration_pass
from rwall_fem.kernels import STEP_SLOTS

__all__ = ["FORMULATIONS", "ShellBody", "ShellSection"]


# The scene's names of the shell formulations.
FORMULATIONS = {
    "bwc": "Belytschko-Lin-Tsay quadrilateral shells with the Belytschko-Wong-Chiang "
    "warping correction",
    "bt": "Belytschko-Lin-Tsay quadrilateral shells",
    "qeph": "Belytschko-Lin-Tsay quadrilateral shells with the warping correction and "
    "QEPH's physical hourglass stiffness (Radioss Ishell 24)",
    "bsc": "Belytschko-Stolarski-Carpenter triangular shells",
}


@dataclass(frozen=True)
class ShellSection:
    """A part's shell section (Radioss /PROP/SHELL): the element ``technology`` of the
    kernels (:class:`~rwall_fem.shells.elements.ShellTechnology`), the scene's
    ``formulation``, the ``thickness`` (m) and the ``points`` through it; the share of
    them that must fail for a cell to fail (``failed_share``, Radioss's P_thickfail), and
    whether the thickness follows the membrane strain (``thickness_change``, Ithick = 1)."""

    technology: object
    formulation: str
    thickness: float
    points: int
    failed_share: float = 1.0
    thickness_change: bool = False

    def describe(self) -> str:
        """E.g. 'Belytschko-Lin-Tsay quadrilateral shells, 5 points through 0.002 m'."""
        change = " (changing with the membrane strain)" if self.thickness_change else ""
        share = (f", a cell failing when {100 * self.failed_share:.3g} % of its points have"
                 if self.failed_share < 1.0 else "")  # fmt: skip
        t = self.technology
        extra = (f", elastic hourglass stiffness {t.hourglass_stiffness:g}"
                 if t.hourglass_stiffness > 0.0 else "")  # fmt: skip
        extra += (f", drilling springs {t.drilling_stiffness:g} G t A"
                  if t.drilling_stiffness > 0.0 else "")  # fmt: skip
        extra += ", QEPH's step length" if t.step_length == "qeph" else ""
        extra += ", QEPH's yielding hourglass forces" if t.hourglass_yield else ""
        return (f"{FORMULATIONS[self.formulation]}, {self.points} points through "
                f"{self.thickness:g} m{change}{share}{extra}")  # fmt: skip


class ShellBody(PartedBody):
    """The internal force and moments of the shell ``parts`` (:class:`~rwall_fem.body.Part`,
    each with its :class:`ShellSection`) on the vector space ``V``, with the displacement
    and velocity fields ``u`` and ``v`` (m, m/s) of the state; ``inertia`` (owned nodes, 2)
    holds the nodes' masses (kg) and rotational inertias (kg m^2). ``force_class`` is the
    shell element force (one per part; ``ShellForce(V, material, technology, u, v, w,
    thickness=, cells=, f=, m=)``, filling nodal forces ``f`` (N) and moments ``m``
    (N m)). ``explicit``: the scene gave its parts.
    """

    conservative = False  # the kernels' stresses follow a path (rate form)
    books_work = True
    corrects = False
    labels = None  # the update books the work of the body as a whole
    controlling_part = 0

    def __init__(self, V, parts, u: GhostedField, v: GhostedField, inertia: np.ndarray,
                 *, explicit: bool = False):  # fmt: skip
        from rwall_fem.shells.elements import ShellForce

        self.V, self.u, self.v = V, u, v
        self.w = GhostedField(V)  # angular velocity w^{n-1/2}, rad/s
        self.f, self.m = GhostedField(V), GhostedField(V)  # N, N m
        self.parts, self.explicit = parts, explicit
        self.inertia = inertia
        self.inv_inertia = 1.0 / inertia[:, 1]
        self.alpha = np.zeros_like(self.w.owned)  # angular acceleration, rad/s^2
        self.elements = [
            ShellForce(V, part.material, part.technology.technology, u, v, self.w,
                       thickness=part.technology.thickness, cells=part.cells, f=self.f,
                       m=self.m, max_flow_stress=_cap(part.material),
                       failed_share=part.technology.failed_share,
                       thickness_change=part.technology.thickness_change)  # fmt: skip
            for part in parts
        ]
        self.nodal_force = self.f.owned
        self.moments = self.m.owned
        self.X = np.ascontiguousarray(V.tabulate_dof_coordinates(), dtype=np.float64)
        owned = V.mesh.topology.index_map(V.mesh.topology.dim).size_local
        self._alone = len(parts) == 1 and len(parts[0].cells) == owned
        self.step = self.elements[0].step if self._alone else np.zeros(STEP_SLOTS)
        self.held = held_nodes(V, self.elements)
        self.part_masses = None  # (owned nodes, parts), kg: set by the builder
        self.rotational_kinetic = 0.0  # the rotations' K^n of the latest update, J
        self.rotational_sums = (0.0, 0.0)  # sum M . w^{n-1/2}, sum M . w^{n+1/2}, W
        self._done = 0.0  # the work of the forces and moments over the finished halves, J
        self._latest = 0.0  # ... up to step n (its first half), J
        self.name = (
            f"shells ({parts[0].material.model})"
            if len(parts) == 1
            else "shells: " + ", ".join(f"{p.name} {p.material.model}" for p in parts)
        )
        self.plastic = any(part.material.plastic for part in parts)
        self._nodes = np.asarray(_compat.cell_nodes(V))  # each local cell's nodes
        owned_nodes = V.dofmap.index_map.size_local
        self._eroded = ErodedParts(parts, self.elements, self.held[:owned_nodes], owned)
        self._name_energies()
        self._free = None  # (owned nodes, 3): 0 where a rotation is held, else 1
        self.turning = None  # (owned nodes,): 0 at a rigid body's nodes (their energy is its)
        self._acceleration = None

    def _name_energies(self) -> None:
        """:attr:`energy_names` (the balance's: the rotations' kinetic, internal, hourglass
        and, when cells may erode, eroded internal energies), :attr:`energy_parts` (beside
        them: elastic and plastic work, the detached nodes' kinetic energy) and
        :attr:`erosion` (None when no cell may erode)."""
        erodes = any(force.erosion is not None for force in self.elements)
        self.energy_names = ("rotational_kinetic", "internal", "hourglass")
        self.energy_parts = ("elastic", "plastic_work") if self.plastic else ()
        if erodes:
            self.energy_names += ("eroded_internal",)
            self.energy_parts += ("eroded_kinetic",)
        self.erosion = self._eroded if erodes else None

    # --- the step ----------------------------------------------------------------------

    def accelerate(self, state) -> None:
        """Set ``state.a = -f(u^n) / m`` and :attr:`alpha` ``= -M / I`` on the owned nodes
        (0 about the held axes), in one compiled sweep after every part's kernel added its
        forces and moments; combine what they noted of the stable steps."""
        for field in (self.u, self.v, self.w):
            field.scatter_forward()
        self.f.array.fill(0.0)
        self.m.array.fill(0.0)
        self._begin_nodal_stiffness()
        for force in self.elements:
            force.compute(state)
        self.f.scatter_reverse_add()
        self.m.scatter_reverse_add()
        self._end_nodal_stiffness()
        if not self._alone:
            self._combine_steps()
        rotations = (self.m.array, self.inv_inertia, self._free, self.alpha)
        self._acceleration = acceleration_pass(self._acceleration, self.f.array,
                                               state.inv_mass, state.a, rotations)  # fmt: skip
        self._acceleration()

    def scale_rotations(self, nodes: np.ndarray, ratio: np.ndarray) -> float:
        """Mass scaling gave the owned ``nodes`` ``ratio`` times their mass: their
        rotational inertia grows as much (else their rotations, whose inertia holds them
        at the membrane's step, would set a step below dt_min), their angular momentum is
        kept, w' = w / ratio, and the kinetic energy this costs is returned (J, <= 0, this
        rank; :mod:`rwall_fem.mass_scaling`)."""
        before = self.inertia[nodes, 1].copy()
        w = self.w.owned[nodes]
        keep = (1.0 / ratio)[:, None]
        work = 0.5 * float(np.sum(before[:, None] * w * w * (keep - 1.0)))
        self.inertia[nodes] *= ratio[:, None]
        self.inv_inertia[nodes] = 1.0 / self.inertia[nodes, 1]
        self.w.owned[nodes] = w * keep
        self.alpha[nodes] *= keep
        return work

    def hold_rotations(self, nodes: np.ndarray, axes: str) -> None:
        """Hold the rotations of the owned ``nodes`` about the global ``axes`` (some of
        "xyz") fixed: their angular velocity stays 0, the reaction moment does no work (a
        clamped edge with the translations held by a boundary condition)."""
        if self._free is None:
            self._free = np.ones_like(self.alpha)
        columns = ["xyz".index(c) for c in axes]
        self._free[np.ix_(nodes, columns)] = 0.0
        self.w.owned[np.ix_(nodes, columns)] = 0.0

    def book(self, state, first: float, second: float) -> None:
        """After the update of step n: book the work of the forces and moments at mid-step
        velocities, dt^n/2 (first + second), from sum f . v^{n-1/2} + M . w^{n-1/2}
        (``first``, with :attr:`rotational_sums`) and the same at n + 1/2 (W); what is
        booked up to step n holds its first half only."""
        dt_v = state.dt_velocity
        first += self.rotational_sums[0]
        second += self.rotational_sums[1]
        self._latest = self._done + 0.5 * dt_v * first
        self._done += 0.5 * dt_v * (first + second)

    # --- energies ----------------------------------------------------------------------

    def energies(self, state) -> dict[str, float]:
        """This rank's energies (J) at step n: the rotations' shadow kinetic energy, the
        internal energy (the work of the forces and moments less the hourglass energy and
        what eroded cells took with them), the hourglass energy and, when cells may erode,
        the eroded cells' internal energy and the detached nodes' kinetic energy
        (:mod:`rwall_fem.erosion`: as for solids)."""
        hourglass = sum(force.hourglass_energy for force in self.elements)
        eroded = sum(force.eroded_energy for force in self.elements)
        energies = {
            "rotational_kinetic": self.rotational_kinetic,
            "internal": self._latest - hourglass - eroded,
            "hourglass": hourglass,
        }
        if self.plastic:
            energies["elastic"] = sum(force.stored_energy for force in self.elements)
            energies["plastic_work"] = sum(force.plastic_work for force in self.elements)
        if self.erosion is not None:
            energies["eroded_internal"] = eroded
            energies["eroded_kinetic"] = self._eroded.kinetic_energy(state)
        return energies

    def part_columns(self) -> tuple[str, ...]:
        """The per-part columns of ``energy.csv``: ``<part>.kinetic`` (translations, by the
        part's share of the nodes' masses), ``<part>.internal`` and ``<part>.hourglass``
        (what its kernel booked of its cells: stored and plastic work; hourglass work)."""
        return tuple(f"{p.name}.{n}" for p in self.parts for n in ("kinetic", "internal",
                                                                    "hourglass"))  # fmt: skip

    def part_values(self, state) -> np.ndarray:
        """This rank's values (J) of :meth:`part_columns` at step n."""
        kinetic = self.part_kinetic(state)
        return np.array(
            [
                value
                for k, force in enumerate(self.elements)
                for value in (kinetic[k], force.stored_energy + force.plastic_work,
                              force.hourglass_energy)  # fmt: skip
            ]
        )

    def step_change_work(self) -> float:
        return 0.0

    # --- the stable step ---------------------------------------------------------------

    estimate_every_step = True  # the frame and the lengths follow the shell every cycle

    def calibrate(self, dt_exact: float, cap: bool = True) -> float:
        """Shells take the elements' estimates as they are (Radioss's L_c / c): the ratio of
        ``dt_exact`` (s, their smallest at rest) to their smallest at rest, 1."""
        smallest = self.V.mesh.comm.allreduce(
            float(self.steps_at_rest().min(initial=np.inf)), op=MPI.MIN
        )
        return dt_exact / smallest

    calibration = 1.0

    def cell_position(self, cell: int) -> np.ndarray:
        """The centroid (m) of the owned ``cell`` (its local index) at X + u."""
        nodes = self._nodes[cell]
        return (self.X[nodes] + self.u.array[nodes]).mean(axis=0)

    def describe_cell(self, cell: int) -> str:
        """The owned ``cell``'s part in words."""
        part, _ = self._locate(cell)
        return f"of part {self.parts[part].name}" if self.explicit else "a shell"

    # --- checkpoints -------------------------------------------------------------------

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The angular velocity w^{n+1/2}, the nodes' masses and rotational inertias (mass
        scaling changes them), the books of the work, the rotations' latest kinetic energy
        and each part's kernel state."""
        arrays = {
            "w": self.w.owned,
            "inertia": self.inertia,
            "books": np.array([self._done, self._latest, self.rotational_kinetic]),
        }
        return arrays | self._element_states()

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.w.owned[:] = arrays["w"]
        if "inertia" in arrays:
            self.inertia[...] = arrays["inertia"]
            self.inv_inertia[:] = 1.0 / self.inertia[:, 1]
        self._done, self._latest, self.rotational_kinetic = arrays["books"].tolist()
        self._restore_elements(arrays)


def _cap(material) -> float:
    """The material's flow-stress cap (Pa; inf: none)."""
    cap = getattr(material, "max_flow_stress", None)
    return math.inf if cap is None else cap

