"""Fields for ParaView, pyvista and meshio: one time series in ``fields.xdmf``.

Each snapshot holds the displacement (m) and the velocity (m/s) at the nodes
and every cell field of the internal force (``sim.internal.cell_fields``, e.g.
the equivalent plastic strain) as piecewise constants (DG0). Unless the
internal force gives a ``von_mises_stress``, the von Mises stress (Pa) is
computed here from the Cauchy stress: Hooke's law for linear elasticity,
sigma = P F^T / J for the hyperelastic models.

DOLFINx writes the data collectively (XDMF with HDF5), so parallel runs give
one file; its XML, though, holds one time series per function, and DOLFINx
0.10+ declares the XInclude namespace with ``https://``, which the XDMF
readers of VTK do not know (pyvista crashes on it). At the end of the run rank
0 rewrites the XML into one temporal collection whose every step carries all
fields, with the ``http://`` namespace (:func:`one_time_series`); the HDF5 file
is left as DOLFINx wrote it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import ufl
from dolfinx import fem, io

from rwall_fem import _compat
from rwall_fem.mechanics import stress
from rwall_fem.output.schedule import spread

__all__ = ["Fields", "one_time_series"]

XINCLUDE = "http://www.w3.org/2001/XInclude"
# The steps after the first take their topology and geometry from the first step.
MESH_POINTER = "xpointer(/Xdmf/Domain/Grid/Grid[1]/*[self::Topology or self::Geometry])"


class Fields:
    """Recorder that writes ``count`` field snapshots of the displacement ``u`` in the space
    ``V`` spread evenly over the ``num_steps`` steps of the run, into ``directory``."""

    def __init__(self, directory: Path, *, count: int, num_steps: int, V, material):
        self.steps = spread(count, num_steps)
        self.path = Path(directory) / "fields.xdmf"
        msh = V.mesh
        self.u, self.v = fem.Function(V), fem.Function(V)
        self.u.name, self.v.name = "displacement", "velocity"
        self._Q = _compat.scalar_space(msh)
        num_cells = msh.topology.index_map(msh.topology.dim).size_local
        self._cell_dofs = _compat.cell_nodes(self._Q)[:num_cells, 0]  # owned cell -> DG0 dof
        self._material, self._mises = material, None  # compiled at its first use
        self._cells: dict[str, fem.Function] = {}
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
        cell_fields = sim.internal.cell_fields(s)
        if "von_mises_stress" not in cell_fields:
            if self._mises is None:
                self._mises = _compat.expression(_von_mises(self.u, self._material), self._Q)
            self._cell_function("von_mises_stress").interpolate(self._mises)
        for name, values in cell_fields.items():
            field = self._cell_function(name)
            field.x.array[self._cell_dofs] = values
            field.x.scatter_forward()
        for field in (self.u, self.v, *self._cells.values()):
            self._file.write_function(field, s.t)

    def _cell_function(self, name: str) -> fem.Function:
        """The DG0 function that holds the cell field ``name``, made at its first use."""
        if name not in self._cells:
            self._cells[name] = fem.Function(self._Q)
            self._cells[name].name = name
        return self._cells[name]

    def close(self, sim) -> None:
        if self._file is None:
            return
        self._file.close()
        if self.u.function_space.mesh.comm.rank == 0:
            one_time_series(self.path)


def one_time_series(path: Path) -> None:
    """Rewrite the XDMF file ``path`` as DOLFINx wrote it (a mesh grid, then one temporal
    collection per function) into one temporal collection whose steps hold every
    attribute of their time, in the order the functions were written; the first step
    holds the mesh, the others include it."""
    root = ET.parse(path).getroot()
    domain = root.find("Domain")
    mesh, *collections = domain.findall("Grid")
    steps: dict[str, list[ET.Element]] = {}  # time value (as written) -> attributes
    for collection in collections:
        for grid in collection.findall("Grid"):
            steps.setdefault(grid.find("Time").get("Value"), []).extend(grid.findall("Attribute"))
    ET.register_namespace("xi", XINCLUDE)
    out = ET.Element("Xdmf", Version="3.0")
    series = ET.SubElement(
        ET.SubElement(out, "Domain"),
        "Grid",
        Name="fields",
        GridType="Collection",
        CollectionType="Temporal",
    )
    for k, time in enumerate(sorted(steps, key=float)):
        step = ET.SubElement(series, "Grid", Name="fields", GridType="Uniform")
        if k == 0:
            step.extend(mesh.findall("*"))  # Topology and Geometry
        else:
            ET.SubElement(step, f"{{{XINCLUDE}}}include", xpointer=MESH_POINTER)
        ET.SubElement(step, "Time", Value=time)
        step.extend(steps[time])
    for item in out.iter("DataItem"):
        # DOLFINx stores doubles and 64-bit integers but leaves the precision out, and
        # VTK's readers take 4 bytes by default (floats rounded to single precision).
        item.set("Precision", "8")
    ET.indent(out)
    Path(path).write_text('<?xml version="1.0"?>\n' + ET.tostring(out, encoding="unicode") + "\n")


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
