"""Watching the stable step while the body deforms (large deformation only).

The run's step dt is fixed at the start from the exact stable step of the body at
rest, ``dt_stable`` (:func:`~rwall_fem.mechanics.critical_time_step`). Large
deformation changes the limit: a hyperelastic body stiffens (the tangent's largest
eigenvalue grows), crushed elements of a plastic body get thin. A monitor
re-estimates the limit as the run goes and stops it (never silently) when dt
exceeds it, saying how far the limit fell and what to lower:

- :class:`TangentStepMonitor` (hyperelastic bodies): the change of the tangent's
  largest eigenvalue, from a warm-started power iteration on the kernels' forces;
- :class:`ElementStepMonitor` (elasto-plastic bodies, whose forces depend on the
  path): the change of the shortest element edge, the element estimate of explicit
  codes, calibrated on the exact limit at rest.

The interval between checks adapts (in steps, between 1 and ``every``): it doubles
while the limit stays put, and shrinks to a quarter of the steps in which the limit,
falling at its latest rate, would reach dt. Checks start one step apart, as an
impact at t = 0 can lower the limit within a few steps.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

from rwall_fem.mechanics import coordinate_pattern, shortest_edge
from rwall_fem.solver import RunStopped

__all__ = ["ElementStepMonitor", "TangentStepMonitor"]


class _StepMonitor:
    """A recorder that stops the run when dt exceeds ``SAFETY`` times the estimate of the
    current stable step given by :meth:`estimate` (s); subclasses say how to estimate."""

    SAFETY = 0.95

    def __init__(self, dt_stable: float, every: int = 50):
        self.dt_stable, self.every = dt_stable, every
        self.estimates = []  # (t, estimated stable step in s) at every check
        self._next, self._interval, self._last = 0, 1, (0, dt_stable)

    def estimate(self, s) -> float:
        raise NotImplementedError

    def due(self, step: int) -> bool:
        return step >= self._next

    def record(self, sim, s) -> None:
        estimate = self.estimate(s)
        self.estimates.append((s.t, estimate))
        limit = self.SAFETY * estimate
        if s.dt > limit:
            raise RunStopped(
                f"step {s.step}, t = {s.t:.6g} s: the deformation lowered the stable step to "
                f"about {limit:.4g} s ({limit / self.dt_stable:.3f} of the initial limit, and it "
                f"may fall further), below dt = {s.dt:.4g} s; lower run.dt_scale"
            )
        last_step, last_estimate = self._last
        fall = (last_estimate - estimate) / max(s.step - last_step, 1)  # s per step
        if fall > 0:
            reach = (limit - s.dt) / (self.SAFETY * fall)  # steps until dt would be exceeded
            self._interval = int(np.clip(reach / 4, 1, 2 * self._interval))
        else:
            self._interval *= 2
        self._interval = min(self._interval, self.every)
        self._last = (s.step, estimate)
        self._next = s.step + self._interval

    def close(self, sim) -> None:
        pass

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The estimates so far and the schedule of the checks."""
        last_step, last_estimate = self._last
        return {
            "estimates": np.array(self.estimates).reshape(-1, 2),
            "schedule": np.array([self._next, self._interval, last_step, last_estimate]),
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.estimates = [tuple(row) for row in arrays["estimates"].tolist()]
        following, interval, last_step, last_estimate = arrays["schedule"].tolist()
        self._next, self._interval = int(following), int(interval)
        self._last = (int(last_step), last_estimate)


class TangentStepMonitor(_StepMonitor):
    """The stable step of a hyperelastic body: ``dt_stable`` (s) scaled by the change of the
    tangent's largest eigenvalue, tracked by a warm-started power iteration on the forces
    of ``force`` (an :class:`~rwall_fem.elements.ElementForce`). The same iteration runs at
    t = 0 and later, so most of its bias cancels in the ratio; a power iteration approaches
    lambda_max from below, so the estimated step errs long (up to 3 % against SLEPc on the
    assembled tangent in the 20 %-of-c impacts of the tests): hence ``SAFETY`` = 0.95."""

    def __init__(self, force, state, dt_stable: float, comm: MPI.Comm, every: int = 50):
        super().__init__(dt_stable, every)
        self.force, self.comm = force, comm
        self._mode = None  # the latest eigenvector estimate
        self.reference = self.largest_eigenvalue(state, iterations=60, tolerance=1e-6)

    def estimate(self, s) -> float:
        ratio = self.largest_eigenvalue(s, iterations=8) / self.reference
        return self.dt_stable / np.sqrt(max(ratio, 1e-300))

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """Also the reference eigenvalue (1/s^2) and the power iteration's latest vector."""
        return super().checkpoint_state() | {
            "reference": np.array(self.reference),
            "mode": self._mode,
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        super().restore_state(arrays)
        self.reference = float(arrays["reference"])
        self._mode = arrays["mode"].copy()

    def largest_eigenvalue(self, state, iterations: int, tolerance: float = 1e-3) -> float:
        """Rayleigh quotient (1/s^2) of a power iteration on M^-1/2 K_t M^-1/2, the tangent
        stiffness K_t applied by finite differences of the internal forces; warm-started
        from the previous call's vector. It stops after ``iterations`` force computations,
        or earlier (after at least two) once the quotient changes by less than
        ``tolerance`` (relative) from one iteration to the next."""
        comm, forces = self.comm, self.force.forces
        scale = np.sqrt(state.inv_mass)
        base = forces(state.u)
        x = self._mode
        if x is None:
            x = coordinate_pattern(state.X)[:, None] * [1, -1, 1]
            x = x / np.sqrt(comm.allreduce(float(np.sum(x * x))))
        size = comm.allreduce(float(np.ptp(state.X, axis=0).max(initial=0.0)), op=MPI.MAX)
        rayleigh = previous = 0.0
        for i in range(iterations):
            dx = scale * x
            # Perturb by 1e-7 of the body size: linear enough, far above round-off.
            largest = comm.allreduce(float(np.abs(dx).max(initial=0.0)), op=MPI.MAX)
            reach = 1e-7 * size / largest
            y = (forces(state.u + reach * dx) - base) / reach * scale
            previous, rayleigh = rayleigh, comm.allreduce(float(np.sum(x * y)))
            x = y / np.sqrt(comm.allreduce(float(np.sum(y * y))))
            if i >= 1 and abs(rayleigh - previous) <= tolerance * abs(rayleigh):
                break
        self._mode = x
        return rayleigh


class ElementStepMonitor(_StepMonitor):
    """The stable step of a body whose elements get crushed: ``dt_stable`` (s) scaled by the
    change of the shortest element edge of the owned cells of ``V`` (the element estimate
    L/c of explicit codes, whose ratio to the exact limit is taken from the body at rest),
    with the nodes at X + u of the displacement field ``u`` (a ghosted field). It also stops
    the run when ``force`` (the elasto-plastic :class:`~rwall_fem.elements.ElementForce`)
    found a cell inverted, as LS-DYNA's negative-volume error does."""

    def __init__(self, V, u, force, dt_stable: float, comm: MPI.Comm, every: int = 50):
        super().__init__(dt_stable, every)
        self.comm, self.V, self.u, self.force = comm, V, u, force
        self.X = V.tabulate_dof_coordinates()
        self.reference = shortest_edge(V, self.X)

    def estimate(self, s) -> float:
        inverted = self.comm.allreduce(self.force.inverted_cells)
        if inverted:
            raise RunStopped(
                f"step {s.step}, t = {s.t:.6g} s: {inverted} element(s) turned inside out "
                "(a non-positive volume): the deformation is too large for the mesh at this "
                "step; lower run.dt_scale or refine the mesh"
            )
        self.u.scatter_forward()
        return self.dt_stable * shortest_edge(self.V, self.X + self.u.array) / self.reference
