"""Large deformation (total Lagrangian): hyperelastic internal forces as an effect.

Selected by ``material.model = "saint_venant_kirchhoff"`` or ``"neo_hookean"``
(compressible). The internal force is the residual of the first Piola-Kirchhoff
stress, f = int P(F) : grad(w) dX with F = I + grad(u), assembled every step
from a form compiled once; the strain energy is int psi(F) dX. At u = 0 both
models have the small-strain stiffness, so the initial stable step is that of
the linear model; :class:`StableStepMonitor` re-estimates it in the current
configuration.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from rwall_fem import _compat
from rwall_fem.mechanics import coordinate_pattern
from rwall_fem.scene import Material
from rwall_fem.solver import RunStopped

__all__ = ["HyperelasticForce", "StableStepMonitor", "strain_energy_density"]

QUADRATURE_DEGREE = 2  # exact for the linearised P1 / Q1 stiffness


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


class HyperelasticForce:
    """Internal force of a hyperelastic body; *sets* ``state.a`` like the linear force."""

    energy_names = ("internal",)

    def __init__(self, V, material: Material, state):
        self.name = material.model
        self.V = V
        self.u = fem.Function(V)
        gdim = V.mesh.geometry.dim
        F = ufl.variable(ufl.Identity(gdim) + ufl.grad(self.u))
        psi = strain_energy_density(F, material)
        P = ufl.diff(psi, F)
        w = ufl.TestFunction(V)
        # One quadrature rule for both forms: the discrete force is then exactly the
        # gradient of the discrete strain energy, which the energy balance relies on.
        dx = ufl.dx(metadata={"quadrature_degree": QUADRATURE_DEGREE})
        self._force = fem.form(ufl.inner(P, ufl.grad(w)) * dx)
        self._energy = fem.form(psi * dx)
        self._vector = _compat.create_vector(V, self._force)
        self._owned = state.u.size
        self._mode = None  # the latest eigenvector estimate of largest_eigenvalue

    def forces(self, u: np.ndarray) -> np.ndarray:
        """Internal forces (N) on the owned nodes for the displacement ``u`` (n, 3), a view."""
        self.u.x.array[: self._owned] = u.ravel()
        self.u.x.scatter_forward()
        b = self._vector
        with b.localForm() as local:
            local.set(0.0)
        fem.petsc.assemble_vector(b, self._force)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        return b.array.reshape(-1, 3)

    def accelerate(self, state) -> None:
        np.multiply(self.forces(state.u), state.inv_mass, out=state.a)
        np.negative(state.a, out=state.a)

    def energies(self, state) -> dict[str, float]:
        """Strain energy (J) of this rank's cells at the displacement of the latest step,
        as ``{"internal": ...}``."""
        return {"internal": fem.assemble_scalar(self._energy)}

    def largest_eigenvalue(self, state, iterations: int, tolerance: float = 1e-3) -> float:
        """Rayleigh quotient (1/s^2) of a power iteration on M^-1/2 K_t M^-1/2, the tangent
        stiffness K_t applied by finite differences of the internal forces; warm-started
        from the previous call's vector. It stops after ``iterations`` force assemblies, or
        earlier (after at least two) once the quotient changes by less than ``tolerance``
        (relative) from one iteration to the next."""
        comm = self.V.mesh.comm
        scale = np.sqrt(state.inv_mass)
        base = self.forces(state.u).copy()
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
            y = (self.forces(state.u + reach * dx) - base) / reach * scale
            previous, rayleigh = rayleigh, comm.allreduce(float(np.sum(x * y)))
            x = y / np.sqrt(comm.allreduce(float(np.sum(y * y))))
            if i >= 1 and abs(rayleigh - previous) <= tolerance * abs(rayleigh):
                break
        self._mode = x
        self.forces(state.u)  # leave the Function at the current displacement
        return rayleigh


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

    def __init__(self, force: HyperelasticForce, state, dt_stable: float, every: int = 50):
        self.force, self.every, self.dt_stable = force, every, dt_stable
        self.reference = force.largest_eigenvalue(state, iterations=60, tolerance=1e-6)
        self.estimates = []  # (t, estimated stable step in s) at every check
        self._next, self._interval, self._last = 0, 1, (0, dt_stable)

    def due(self, step: int) -> bool:
        return step >= self._next

    def record(self, sim, s) -> None:
        ratio = self.force.largest_eigenvalue(s, iterations=8) / self.reference
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

    def close(self, sim) -> None:
        pass
