"""Mass scaling: mass added to the cells whose stable step would fall below ``run.dt_min``
(LS-DYNA's DT2MS < 0, Radioss's /DT/.../CST), just enough to hold the step there.

A cell's stable step grows as the square root of its mass (dt_e = L / c, c^2 = M / rho):
a cell whose estimate dt_e is below the floor gets its mass multiplied by
(floor / dt_e)^2, the added mass shared equally among its nodes. Cells keep what they
got; it grows as they are crushed further. The kernels then scale the cell's estimate by
sqrt(m / m_0) (:meth:`~rwall_fem.elements.ElementForce.list_cells_below`). A body of
parts scales each part's cells with the density of its material.

The added mass joins a node at rest: the node keeps its momentum, m v = (m + dm) v', so
that momentum is conserved to round-off, and the kinetic energy this costs,
1/2 m |v|^2 dm / (m + dm), is booked as work (``mass_scaling_work`` < 0) so that the
energy balance still closes. The half-step works of the walls and boundary conditions
of the previous step are settled with the velocities before the change.

The added mass is booked in ``energy.csv`` (kg and % of the body's), ``summary.json``
and ``run.log``; past ``run.max_added_mass`` (a fraction of the body's mass) the run
stops.
"""

from __future__ import annotations

import numpy as np
from dolfinx import la

from rwall_fem import _compat

__all__ = ["MassScaling"]


class MassScaling:
    """Adds mass to the cells of the ``body`` (a :class:`~rwall_fem.body.Body`, on the
    space ``V``) whose step would go below ``floor`` (s); ``body_mass`` (kg) is the body's
    mass at rest, ``max_fraction`` the share of it that may be added before the run
    stops."""

    def __init__(self, body, V, body_mass: float, max_fraction: float, floor: float):
        self.body, self.comm = body, V.mesh.comm
        self.body_mass, self.max_fraction = body_mass, max_fraction
        self._owned = V.dofmap.index_map.size_local
        self._nodal = la.vector(V.dofmap.index_map, len(body.elements))  # added, per part
        # Per part: each cell's mass over its mass at rest, its square root (read by the
        # kernels) and its mass at rest (kg).
        self.ratios, self.factors, self.cell_masses = [], [], []
        for part, force in zip(body.parts, body.elements, strict=True):
            self.ratios.append(np.ones(force.num_cells))
            self.factors.append(np.ones(force.num_cells))
            self.cell_masses.append(part.material.density * force.volume0)
            force.list_cells_below(floor, self.factors[-1])
        self.added = 0.0  # kg, all ranks
        self.work = 0.0  # J, this rank: the kinetic energy the joining masses cost (<= 0)
        self.cells = 0  # cells scaled so far, all ranks

    @property
    def added_percent(self) -> float:
        """The added mass in % of the body's mass at rest."""
        return 100.0 * self.added / self.body_mass

    def add(self, sim, s, floor: float) -> str | None:
        """Give the cells listed by the latest kernel pass (on any rank) the mass that brings
        their step to ``floor`` (s) (collective: every rank calls it when one listed
        cells); returns a reason to stop when the added mass passes the limit."""
        count = len(self.body.elements)
        nodal = self._nodal.array.reshape(-1, count)
        nodal[:] = 0.0
        fresh, extra_total = 0, 0.0
        for k, force in enumerate(self.body.elements):
            listed = int(force.step[10])
            cells, steps = force.below[:listed], force.below_step[:listed]
            ratio = self.ratios[k]
            needed = np.maximum((floor / steps) ** 2 * (1.0 + 1e-12), ratio[cells])
            fresh += int(np.count_nonzero(ratio[cells] == 1.0))
            extra = self.cell_masses[k][cells] * (needed - ratio[cells])  # kg per cell
            ratio[cells] = needed
            self.factors[k][cells] = np.sqrt(needed)
            nodes = force.cells[cells]
            share = np.repeat(extra / nodes.shape[1], nodes.shape[1])
            np.add.at(nodal[:, k], nodes.ravel(), share)
            extra_total += float(extra.sum())
        _compat.scatter_reverse_add(self._nodal)
        added = nodal[: self._owned]
        changed = np.flatnonzero(added.sum(axis=1) > 0.0)
        for constraint in sim.constraints:  # their previous step, with the velocities before
            constraint.settle(s)
        for force in sim.forces:
            if hasattr(force, "settle"):
                force.settle(s)
        before = s.mass[changed]
        after = before + added[changed].sum(axis=1)
        keep = (before / after)[:, None]
        v = s.v[changed]
        self.work += 0.5 * float(np.sum(before[:, None] * v * v * (keep - 1.0)))
        s.v[changed] = v * keep
        s.a[changed] *= keep
        s.set_mass(changed, after)
        rotations = getattr(self.body, "scale_rotations", None)
        if rotations is not None:  # shells: the rotational inertia grows with the mass
            self.work += rotations(changed, after / before)
        self.body.part_masses[changed] += added[changed]
        self.added += self.comm.allreduce(extra_total)
        self.cells += self.comm.allreduce(fresh)
        if self.added > self.max_fraction * self.body_mass:
            return (
                f"step {s.step}, t = {s.t:.6g} s: mass scaling has added {self.added:.4g} kg, "
                f"{self.added_percent:.3g} % of the body's mass, more than run.max_added_mass = "
                f"{self.max_fraction:g}; raise it, or lower run.dt_min"
            )
        return None

    def summary(self) -> dict:
        """The mass scaling's part of ``summary.json`` (collective)."""
        return {
            "added_mass": self.added,
            "added_mass_percent": self.added_percent,
            "scaled_cells": self.cells,
            "mass_scaling_work": self.comm.allreduce(self.work),
        }

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The cells' mass ratios and what was booked."""
        arrays = {f"ratio{k}": ratio for k, ratio in enumerate(self.ratios)}
        return arrays | {"books": np.array([self.added, self.work, self.cells])}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        for k, ratio in enumerate(self.ratios):
            ratio[:] = arrays[f"ratio{k}"]
            self.factors[k][:] = np.sqrt(ratio)
        added, self.work, cells = arrays["books"].tolist()
        self.added, self.cells = added, int(cells)
