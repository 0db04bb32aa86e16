"""Large deformation (total Lagrangian): the hyperelastic laws and their stable step.

Selected by ``material.model = "saint_venant_kirchhoff"`` or ``"neo_hookean"``
(compressible). The element kernels compute the internal force
f = int P(F) : grad(w) dX, F = I + grad(u), and the strain energy int psi(F) dX;
:func:`strain_energy_density` is the same law in UFL, the reference the tests
compare the kernels against and the field output's stress. At u = 0 both models
have the small-strain stiffness, so the initial stable step is that of the linear
model; :class:`StableStepMonitor` re-estimates it in the current configuration.
"""

from __future__ import annotations

import numpy as np
import ufl
from mpi4py import MPI

from rwall_fem.mechanics import coordinate_pattern
from rwall_fem.scene import Material
from rwall_fem.solver import RunStopped

__all__ = ["StableStepMonitor", "strain_energy_density"]


def strain_energy_density(F, material: Material):
    """psi(F) in J/m^3 for the material's hyperelastic model."""
    lmbda, mu = material.lame
    d = F.ufl_shape[0]
    if material.model == "saint_venant_kirchhoff":
        E = 0.5 * (F.T * F - ufl.Identity(d))
        return 0.5 * lmbda * ufl.tr(E) ** 2 + mu * ufl.inner(E, E)
    if material.model == "neo_hookean":
        J = ufl.det(F)
        return 0.5 * mu * (ufl.tr(F.T * F) - d) - mu * ufl.ln(J) + 0.5 * lmbda * ufl.ln(J) ** 2
    raise ValueError(f"no hyperelastic model {material.model!r}")


class StableStepMonitor:
    """Re-estimates the stable step of a hyperelastic body as the deformation changes, and
    stops the run (never silently) when the step in use exceeds it.

    The estimate scales the exact initial limit ``dt_stable`` (s) by the change of the
    tangent's largest eigenvalue, tracked by a warm-started power iteration (the same
    iteration at t = 0 and later, so most of its bias cancels in the ratio). A power
    iteration approaches lambda_max from below, so the estimated step errs long: up to
    3 % against SLEPc on the assembled tangent in the 20 %-of-c impacts of the tests;
    the monitor therefore counts ``SAFETY`` = 0.95 of it as the limit.

    The interval between checks adapts (in steps, between 1 and ``every``): it doubles
    while the limit stays put, and shrinks to a quarter of the steps in which the limit,
    falling at its latest rate, would reach dt. Checks start one step apart, as an
    impact at t = 0 can lower the limit within a few steps.
    """

    SAFETY = 0.95

    def __init__(self, force, state, dt_stable: float, comm: MPI.Comm, every: int = 50):
        self.force, self.comm, self.every, self.dt_stable = force, comm, every, dt_stable
        self._mode = None  # the latest eigenvector estimate
        self.reference = self.largest_eigenvalue(state, iterations=60, tolerance=1e-6)
        self.estimates = []  # (t, estimated stable step in s) at every check
        self._next, self._interval, self._last = 0, 1, (0, dt_stable)

    def largest_eigenvalue(self, state, iterations: int, tolerance: float = 1e-3) -> float:
        """Rayleigh quotient (1/s^2) of a power iteration on M^-1/2 K_t M^-1/2, the tangent
        stiffness K_t applied by finite differences of the internal forces (``forces`` of
        the :class:`~rwall_fem.elements.ElementForce`); warm-started from the previous
        call's vector. It stops after ``iterations`` force computations, or earlier (after
        at least two) once the quotient changes by less than ``tolerance`` (relative) from
        one iteration to the next."""
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

    def due(self, step: int) -> bool:
        return step >= self._next

    def record(self, sim, s) -> None:
        ratio = self.largest_eigenvalue(s, iterations=8) / self.reference
        estimate = self.dt_stable / np.sqrt(max(ratio, 1e-300))
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

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The reference eigenvalue (1/s^2), the power iteration's latest vector, the
        estimates so far and the schedule of the checks."""
        last_step, last_estimate = self._last
        return {
            "reference": np.array(self.reference),
            "mode": self._mode,
            "estimates": np.array(self.estimates).reshape(-1, 2),
            "schedule": np.array([self._next, self._interval, last_step, last_estimate]),
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.reference = float(arrays["reference"])
        self._mode = arrays["mode"].copy()
        self.estimates = [tuple(row) for row in arrays["estimates"].tolist()]
        following, interval, last_step, last_estimate = arrays["schedule"].tolist()
        self._next, self._interval = int(following), int(interval)
        self._last = (int(last_step), last_estimate)

    def close(self, sim) -> None:
        pass
