"""Fields for ParaView: displacement, velocity and von Mises stress in ``fields.xdmf``.

Written collectively by all ranks (XDMF with HDF5), so parallel runs give one
file. The von Mises stress is a cell value (DG0) of the Cauchy stress: Hooke's
law for linear elasticity, sigma = P F^T / J for the hyperelastic models.
"""

from __future__ import annotations

from pathlib import Path

import ufl
from dolfinx import fem, io

from rwall_fem import _compat
from rwall_fem.mechanics import stress
from rwall_fem.output.schedule import spread

__all__ = ["Fields"]


class Fields:
    """Recorder that writes ``count`` field snapshots of the displacement ``u`` in the space
    ``V`` spread evenly over the ``num_steps`` steps of the run, into ``directory``."""

    def __init__(self, directory: Path, *, count: int, num_steps: int, V, material):
        self.steps = spread(count, num_steps)
        self.path = Path(directory) / "fields.xdmf"
        msh = V.mesh
        self.u, self.v = fem.Function(V), fem.Function(V)
        self.u.name, self.v.name = "displacement", "velocity"
        Q = _compat.scalar_space(msh)
        self.mises = fem.Function(Q)
        self.mises.name = "von_mises_stress"
        self._mises = _compat.expression(_von_mises(self.u, material), Q)
        self._file = None

    def due(self, step: int) -> bool:
        return step in self.steps

    def record(self, sim, s) -> None:
        if self._file is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = io.XDMFFile(self.u.function_space.mesh.comm, str(self.path), "w")
            self._file.write_mesh(self.u.function_space.mesh)
        for field, values in ((self.u, s.u), (self.v, s.v)):
            field.x.array[: values.size] = values.ravel()
            field.x.scatter_forward()
        self.mises.interpolate(self._mises)
        for field in (self.u, self.v, self.mises):
            self._file.write_function(field, s.t)

    def close(self, sim) -> None:
        if self._file is not None:
            self._file.close()


def _von_mises(u, material):
    """von Mises equivalent (Pa) of the Cauchy stress of ``material`` at displacement ``u``."""
    if material.model == "linear_elastic":
        sigma = stress(u, material)
    else:
        from rwall_fem.hyperelasticity import strain_energy_density

        F = ufl.variable(ufl.Identity(len(u)) + ufl.grad(u))
        P = ufl.diff(strain_energy_density(F, material), F)
        sigma = P * F.T / ufl.det(F)
    deviator = sigma - ufl.tr(sigma) / 3 * ufl.Identity(len(u))
    return ufl.sqrt(1.5 * ufl.inner(deviator, deviator))
