"""Fields for ParaView, pyvista and meshio: one time series in ``fields.xdmf``.

Each snapshot holds the displacement (m) and the velocity (m/s) at the nodes
and every cell field of the internal force (``sim.internal.cell_fields``, e.g.
the equivalent plastic strain, and the part of each cell of a body of parts) as
piecewise constants (DG0). The von Mises stress (Pa) of the elastic parts is
computed here from the Cauchy stress: Hooke's law for linear elasticity,
sigma = P F^T / J for the hyperelastic models; the elasto-plastic parts give theirs.
With contact, each snapshot also holds the nodal contact force (N) and contact pressure
(Pa) of the step (:mod:`rwall_fem.output.contact_loads`).

DOLFINx writes the data collectively (XDMF with HDF5), so parallel runs give
one file; its XML, though, holds one time series per function, and DOLFINx
0.10+ declares the XInclude namespace with ``https://``, which the XDMF
readers of VTK do not know (pyvista crashes on it). Whenever the file is
closed, rank 0 rewrites the XML into one temporal collection whose every step
carries all fields, with the ``http://`` namespace (:func:`one_time_series`);
the HDF5 file is left as DOLFINx wrote it. Before DOLFINx appends to the file
again, rank 0 gives the XML back its DOLFINx layout (:func:`series_per_field`).

A checkpoint closes the file (HDF5 holds data in memory until then); the run appends
to it afterwards, and a resumed run skips the snapshots already in it (those written
after its checkpoint: the same ones, as the run is deterministic).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import ufl
from dolfinx import fem, io

from rwall_fem import _compat
from rwall_fem.mechanics import stress
from rwall_fem.output.schedule import Times

__all__ = ["Fields", "one_time_series", "series_per_field"]

XINCLUDE = "http://www.w3.org/2001/XInclude"
# The steps after the first take their topology and geometry from the first step.
MESH_POINTER = "xpointer(/Xdmf/Domain/Grid/Grid[1]/*[self::Topology or self::Geometry])"
# In DOLFINx's layout every step takes them from the mesh grid, the first uniform grid.
DOLFINX_POINTER = (
    "xpointer(/Xdmf/Domain/Grid[@GridType='Uniform'][1]/*[self::Topology or self::Geometry])"
)


class Fields:
    """Recorder that writes ``count`` field snapshots of the body (space ``V``, its
    ``parts``: :class:`~rwall_fem.body.Part`) at times spread evenly over
    [0, ``end_time``] (s), into ``directory``; ``contact``: the run's
    :class:`~rwall_fem.output.contact_loads.ContactLoads`, or None without contact."""

    def __init__(self, directory: Path, *, count: int, end_time: float, V, parts,
                 contact=None):  # fmt: skip
        self.steps = Times(count, end_time)
        self.path = Path(directory) / "fields.xdmf"
        msh = V.mesh
        self.u, self.v = fem.Function(V), fem.Function(V)
        self.u.name, self.v.name = "displacement", "velocity"
        self._Q = _compat.scalar_space(msh)
        self._contact = contact
        self._loads = ()  # the contact force and pressure, made at the first snapshot
        num_cells = msh.topology.index_map(msh.topology.dim).size_local
        self._cell_dofs = _compat.cell_nodes(self._Q)[:num_cells, 0]  # owned cell -> DG0 dof
        # The elastic parts' von Mises stress, from the displacement: (cells' DG0 dofs,
        # its expression, compiled at its first use) per part.
        self._elastic = [(self._cell_dofs[p.cells], p.material) for p in parts
                         if not p.material.plastic]  # fmt: skip
        self._mises: list | None = None
        self._scratch = None
        self._cells: dict[str, fem.Function] = {}
        self._file = None
        self._count = 0  # snapshots recorded
        self._present = 0  # snapshots in the file when the run resumed

    def due(self, s) -> bool:
        return self.steps.due(s)

    def record(self, sim, s) -> None:
        self.steps.taken(s)
        index, self._count = self._count, self._count + 1
        if index < self._present:
            return  # written before a resume, after the checkpoint: the same snapshot
        if self._file is None:
            msh = self.u.function_space.mesh
            self.path.parent.mkdir(parents=True, exist_ok=True)
            if index:
                self._per_field()
            self._file = io.XDMFFile(msh.comm, str(self.path), "a" if index else "w")
            if not index:
                self._file.write_mesh(msh)
        for field, values in ((self.u, s.u), (self.v, s.v)):
            field.x.array[: values.size] = values.ravel()
            field.x.scatter_forward()
        cell_fields = sim.internal.cell_fields(s)
        for name, values in cell_fields.items():
            field = self._cell_function(name)
            field.x.array[self._cell_dofs] = values
            field.x.scatter_forward()
        if self._elastic:
            self._elastic_mises()
        if self._contact is not None:
            self._contact_loads(s)
        for field in (self.u, self.v, *self._loads, *self._cells.values()):
            self._file.write_function(field, s.t)

    def _contact_loads(self, s) -> None:
        """The nodal contact force (N) and contact pressure (Pa) of the step."""
        if not self._loads:
            V = self.u.function_space
            nodal = _compat.scalar_space(V.mesh, "Lagrange", 1)
            force, pressure = fem.Function(V), fem.Function(nodal)
            force.name, pressure.name = "contact_force", "contact_pressure"
            self._loads = (force, pressure)
        force, pressure = self._loads
        values = self._contact.force()
        force.x.array[: values.size] = values.ravel()
        values = self._contact.pressure(s)
        pressure.x.array[: values.size] = values
        for field in self._loads:
            field.x.scatter_forward()

    def _elastic_mises(self) -> None:
        """The von Mises stress of the elastic parts' cells, from the displacement."""
        if self._mises is None:
            self._mises = [_compat.expression(_von_mises(self.u, m), self._Q)
                           for _, m in self._elastic]  # fmt: skip
            self._scratch = fem.Function(self._Q)
        field = self._cell_function("von_mises_stress")
        for (dofs, _), expression in zip(self._elastic, self._mises, strict=True):
            self._scratch.interpolate(expression)
            field.x.array[dofs] = self._scratch.x.array[dofs]
        field.x.scatter_forward()

    def _cell_function(self, name: str) -> fem.Function:
        """The DG0 function that holds the cell field ``name``, made at its first use."""
        if name not in self._cells:
            self._cells[name] = fem.Function(self._Q)
            self._cells[name].name = name
        return self._cells[name]

    def close(self, sim) -> None:
        """Close the file (a checkpoint closes it too) and make it one time series."""
        if self._file is None:
            return
        self._file.close()
        self._file = None
        if self.u.function_space.mesh.comm.rank == 0:
            one_time_series(self.path)

    def _per_field(self) -> None:
        """Give the file DOLFINx's layout back before DOLFINx appends to it (collective)."""
        comm = self.u.function_space.mesh.comm
        if comm.rank == 0:
            series_per_field(self.path)
        comm.barrier()

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """How many snapshots are written (the file is closed, so they are on disk), and
        the next time to write."""
        self.close(None)
        return {"snapshots": np.array(self._count), "next": np.array(self.steps.next)}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Continue the file: it must hold the checkpoint's snapshots, whole."""
        comm = self.u.function_space.mesh.comm
        self.steps.next = int(arrays["next"])
        self._count, counts, error = int(arrays["snapshots"]), set(), None
        if comm.rank == 0 and self._count:
            try:
                series_per_field(self.path)
                domain = ET.parse(self.path).getroot().find("Domain")
                collections = domain.findall("Grid[@CollectionType='Temporal']")
                counts = {len(c.findall("Grid")) for c in collections}
                if {self.u.name, self.v.name} - {c.get("Name") for c in collections}:
                    counts.add(0)
            except (OSError, ET.ParseError, AttributeError) as err:
                error = f"{self.path}: cannot be read ({err})"
            if not error and (len(counts) > 1 or min(counts) < self._count):
                error = (
                    f"{self.path}: holds snapshots {sorted(counts)} of its fields; the "
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


def one_time_series(path: Path) -> None:
    """Rewrite the XDMF file ``path`` as DOLFINx wrote it (a mesh grid, then one temporal
    collection per function) into one temporal collection whose steps hold every
    attribute of their time, in the order the functions were written; the first step
    holds the mesh, the others include it. A file in that form already is left as it is."""
    root = ET.parse(path).getroot()
    domain = root.find("Domain")
    mesh = domain.find("Grid[@GridType='Uniform']")
    if mesh is None:
        return
    steps: dict[str, list[ET.Element]] = {}  # time value (as written) -> attributes
    for collection in domain.findall("Grid[@CollectionType='Temporal']"):
        for grid in collection.findall("Grid"):
            steps.setdefault(grid.find("Time").get("Value"), []).extend(grid.findall("Attribute"))
    series = ET.Element("Grid", Name="fields", GridType="Collection", CollectionType="Temporal")
    for k, time in enumerate(sorted(steps, key=float)):
        step = ET.SubElement(series, "Grid", Name="fields", GridType="Uniform")
        if k == 0:
            step.extend(mesh.findall("*"))  # Topology and Geometry
        else:
            ET.SubElement(step, f"{{{XINCLUDE}}}include", xpointer=MESH_POINTER)
        ET.SubElement(step, "Time", Value=time)
        step.extend(steps[time])
    for item in series.iter("DataItem"):
        # DOLFINx stores doubles and 64-bit integers but leaves the precision out, and
        # VTK's readers take 4 bytes by default (floats rounded to single precision).
        item.set("Precision", "8")
    _write(path, [series])


def series_per_field(path: Path) -> None:
    """Rewrite the XDMF file ``path`` made by :func:`one_time_series` into DOLFINx's layout
    (a mesh grid, then one temporal collection per field), to which DOLFINx can append.
    A file in that form already is left as it is."""
    domain = ET.parse(path).getroot().find("Domain")
    if domain.find("Grid[@GridType='Uniform']") is not None:
        return
    steps = domain.find("Grid").findall("Grid")
    mesh = ET.Element("Grid", Name="mesh", GridType="Uniform")
    mesh.extend(steps[0].findall("Topology") + steps[0].findall("Geometry"))
    grids, series = [mesh], {}
    for step in steps:
        time = step.find("Time").get("Value")
        for attribute in step.findall("Attribute"):
            name = attribute.get("Name")
            if name not in series:
                series[name] = ET.Element(
                    "Grid", Name=name, GridType="Collection", CollectionType="Temporal"
                )
                grids.append(series[name])
            grid = ET.SubElement(series[name], "Grid", Name=name, GridType="Uniform")
            ET.SubElement(grid, f"{{{XINCLUDE}}}include", xpointer=DOLFINX_POINTER)
            ET.SubElement(grid, "Time", Value=time)
            grid.append(attribute)
    _write(path, grids)


def _write(path: Path, grids: list[ET.Element]) -> None:
    """Write an XDMF file whose domain holds ``grids``."""
    ET.register_namespace("xi", XINCLUDE)
    root = ET.Element("Xdmf", Version="3.0")
    ET.SubElement(root, "Domain").extend(grids)
    ET.indent(root)
    text = ET.tostring(root, encoding="unicode")
    Path(path).write_text('<?xml version="1.0"?>\n' + text + "\n")


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
