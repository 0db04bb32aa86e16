"""Fields for ParaView: displacement, velocity and von Mises stress in ``fields.xdmf``.

Written collectively by all ranks (XDMF with HDF5), so parallel runs give one
file. The von Mises stress is a cell value (DG0) of the Cauchy stress: Hooke's
law for linear elasticity, sigma = P F^T / J for the hyperelastic models.

A checkpoint closes the file (HDF5 holds data in memory until then); the run appends
to it afterwards, and a resumed run skips the snapshots already in it (those written
after its checkpoint: the same ones, as the run is deterministic).
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
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
        self._count = 0  # snapshots recorded
        self._present = 0  # snapshots in the file when the run resumed

    def due(self, step: int) -> bool:
        return step in self.steps

    def record(self, sim, s) -> None:
        index, self._count = self._count, self._count + 1
        if index < self._present:
            return  # written before a resume, after the checkpoint: the same snapshot
        if self._file is None:
            msh = self.u.function_space.mesh
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = io.XDMFFile(msh.comm, str(self.path), "a" if index else "w")
            if not index:
                self._file.write_mesh(msh)
        for field, values in ((self.u, s.u), (self.v, s.v)):
            field.x.array[: values.size] = values.ravel()
            field.x.scatter_forward()
        self.mises.interpolate(self._mises)
        for field in (self.u, self.v, self.mises):
            self._file.write_function(field, s.t)

    def close(self, sim) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """How many snapshots are written; the file is closed, so they are on disk."""
        self.close(None)
        return {"snapshots": np.array(self._count)}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Continue the file: it must hold the checkpoint's snapshots, whole."""
        comm = self.u.function_space.mesh.comm
        self._count, counts, error = int(arrays["snapshots"]), set(), None
        if comm.rank == 0 and self._count:
            try:
                domain = ElementTree.parse(self.path).getroot().find("Domain")
                names = [f.name for f in (self.u, self.v, self.mises)]
                collections = [domain.find(f"Grid[@Name='{name}']") for name in names]
                counts = {len(c.findall("Grid")) if c is not None else 0 for c in collections}
            except (OSError, ElementTree.ParseError, AttributeError) as err:
                error = f"{self.path}: cannot be read ({err})"
            if not error and (len(counts) > 1 or min(counts) < self._count):
                error = (
                    f"{self.path}: holds snapshots {sorted(counts)} of u, v, von Mises; the "
                    f"checkpoint has {self._count} of each"
                )
        self._present, error = comm.bcast((max(counts, default=0), error), root=0)
        if not error and self._count:
            try:  # a run killed while it wrote may leave the HDF5 file unreadable
                io.XDMFFile(comm, str(self.path), "a").close()
            except RuntimeError as err:
                error = f"{self.path}: cannot be appended to ({err})"
        if error:
            raise ValueError(error)


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
