"""The body: its parts, each a material and an element technology over some of the cells
(Radioss ``/PART``, LS-DYNA ``*PART``), and the internal force of them all.

A scene's ``[[part]]`` tables name regions of the mesh (gmsh physical volumes); without
them the body is one part, "body", of every cell. :func:`parts_of` finds each part's
cells (refusing cells in no part, or a part of no cell). :class:`Body` is the internal
force of the pipeline: each part's :class:`~rwall_fem.elements.ElementForce` adds its
force into one field, scattered in reverse and divided by the masses once.

Parts that share nodes are bonded: the nodes are the body's. The energy books go part by
part, as LS-DYNA's MATSUM does, and add up to the body's to round-off:

- a part's stored energy (elastic laws) is its cells';
- a part without a stored energy (plasticity, the viscous hourglass form) books the work
  of its own forces at mid-step velocities: on the nodes that only its cells hold they are
  the body's (the update pass sums them part by part, after :attr:`Body.labels`); at the
  nodes its cells share with another part, its cells' own: what its kernel pass added to
  the body's force there (:meth:`Body.accelerate` takes the difference);
- a node's kinetic energy and momentum go to the parts by their shares of its mass.

When the step varies, a stored energy misses what the changes of the step take out of
K + U: :meth:`Body.step_change_work` books it (``docs/theory.md``, "Energy balance").
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from dolfinx import la
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.elements import ElementForce, GhostedField, Technology
from rwall_fem.erosion import ErodedParts, ErodingBody
from rwall_fem.internal_force import acceleration_pass
from rwall_fem.kernels import STEP_SLOTS

__all__ = [
    "Body",
    "Part",
    "PartedBody",
    "PartError",
    "part_masses",
    "parts_of",
    "piece_overlaps",
    "shared_velocities",
    "technologies",
]


@dataclass
class Part:
    """A part: its ``name``, the local indices of its owned ``cells``, its ``material`` (a
    :class:`~rwall_fem.scene.Material`), element ``technology`` (a solid's
    :class:`~rwall_fem.elements.Technology`, a shell's
    :class:`~rwall_fem.shells.body.ShellSection`) and initial ``velocity`` (m/s)."""

    name: str
    cells: np.ndarray
    material: object
    technology: object
    velocity: tuple[float, float, float]


class PartError(ValueError):
    """The parts do not fit the mesh; the message is one line naming what and where."""


def technologies(specs, cell: str, explicit: bool) -> list[Technology]:
    """The element technology of each resolved part of ``specs`` on cells of type ``cell``;
    a :class:`PartError` naming the part's key (``part[i].element...`` when the scene gave
    ``explicit`` parts) for a combination that does not exist."""
    chosen = []
    for i, spec in enumerate(specs):
        element = spec.element
        try:
            chosen.append(
                Technology.choose(
                    cell,
                    element.integration,
                    element.hourglass,
                    element.hourglass_coefficient,
                    plastic=spec.material.plastic,
                )
            )
        except ValueError as err:  # e.g. reduced integration on a file of tetrahedra
            where = f"part[{i}]." if explicit else ""
            raise PartError(f"{where}{err} (the mesh has {cell} cells)") from None
    return chosen


def parts_of(specs, body_mesh, technologies: list[Technology], comm) -> list[Part]:
    """The :class:`Part` of each of a scene's resolved parts ``specs`` (its
    :attr:`~rwall_fem.scene.Scene.body_parts`) on ``body_mesh`` (a
    :class:`~rwall_fem.meshing.BodyMesh`), with the ``technologies`` chosen for them.

    Raises :class:`PartError` for a region the mesh does not have, regions of cells in no
    part, or a part of no cell (collective: the same on every rank)."""
    msh = body_mesh.msh
    owned = msh.topology.index_map(msh.topology.dim).size_local
    if len(specs) == 1 and not specs[0].volumes:
        spec = specs[0]
        cells = np.arange(owned, dtype=np.int32)
        return [Part(spec.name, cells, spec.material, technologies[0], spec.initial.velocity)]
    volumes = body_mesh.volumes or {"body": 0}
    tags = np.zeros(owned, dtype=np.int64)
    if body_mesh.cell_tags is not None:
        kept = body_mesh.cell_tags.indices < owned
        tags[body_mesh.cell_tags.indices[kept]] = body_mesh.cell_tags.values[kept]
    claimed = np.zeros(owned, dtype=bool)
    parts = []
    for i, spec in enumerate(specs):
        for name in spec.volumes:
            if name not in volumes:
                from rwall_fem.scene.keys import did_you_mean

                raise PartError(
                    f"part[{i}].volumes: the mesh has no region {name!r}"
                    f"{did_you_mean(name, list(volumes))}; its regions: {', '.join(volumes)}"
                )
        mine = np.isin(tags, [volumes[name] for name in spec.volumes])
        if not comm.allreduce(int(mine.sum())):
            raise PartError(f"part[{i}] ({spec.name}): its regions hold no cell")
        claimed |= mine
        cells = np.flatnonzero(mine).astype(np.int32)
        parts.append(Part(spec.name, cells, spec.material, technologies[i], spec.initial.velocity))
    left = {name: comm.allreduce(int(np.count_nonzero(~claimed & (tags == tag))))
            for name, tag in volumes.items()}  # fmt: skip
    lost = ", ".join(f"'{name}' ({n} cells)" for name, n in left.items() if n)
    if lost:
        raise PartError(f"part: the regions {lost} are in no part: name them in a [[part]]")
    return parts


class PartedBody(ErodingBody):
    """What a body of parts does alike, of solids (:class:`Body`) or of shells
    (:class:`~rwall_fem.shells.body.ShellBody`): over its ``parts`` (each with the local
    indices of its owned ``cells``) on the space ``V``, their element forces ``elements``
    (in the order of the parts) and ``part_masses`` ((owned nodes, parts), kg); ``step``
    (what the kernels noted of the stable steps) and ``explicit`` (the scene gave its
    parts)."""

    _nodal = None  # the cells' nodal term of the step (track_nodal_stiffness), a la vector

    def track_nodal_stiffness(self, surface: np.ndarray) -> np.ndarray:
        """From now on, every pass gives each node the sum over its cells of m_c / dt_e^2
        (N/m; m_c the mass the cell gives it, dt_e the cell's calibrated estimate) in the
        returned array (a row per node: complete on the owned rows, changed in place only),
        for the nodal stable step of contact (docs/theory.md, contact's "Stable step"):
        at least at the nodes ``surface`` (a bool per node row, owned and ghost), whose cells
        alone add it."""
        if self._nodal is None:
            self._nodal = la.vector(self.V.dofmap.index_map, 1)
            for part, force in zip(self.parts, self.elements, strict=True):
                force.note_nodal_stiffness(self._nodal.array, float(part.material.density),
                                           surface)  # fmt: skip
        return self._nodal.array

    def _begin_nodal_stiffness(self) -> None:
        """Zero the nodal term before the parts' passes."""
        if self._nodal is not None:
            self._nodal.array.fill(0.0)

    def _end_nodal_stiffness(self) -> None:
        """The ghosts' shares of the nodal term to their owners, after the passes."""
        if self._nodal is not None and self.V.mesh.comm.size > 1:
            _compat.scatter_reverse_add(self._nodal)

    def _combine_steps(self) -> None:
        """:attr:`step` from the parts' notes: the smallest estimate, its cell (an index
        among the owned cells) and place, the inverted cells."""
        best = min(range(len(self.elements)), key=lambda k: self.elements[k].step[0])
        self.controlling_part = best
        step, mine = self.step, self.elements[best].step
        step[:5] = mine[:5]
        if mine[1] >= 0:
            step[1] = self.parts[best].cells[int(mine[1])]
        step[5], step[6], step[10], step[11] = 0.0, -1.0, 0.0, 0.0
        for part, force in zip(self.parts, self.elements, strict=True):
            if force.step[5] and not step[5]:
                step[6] = part.cells[int(force.step[6])]
                step[7:10] = force.step[7:10]
            step[5] += force.step[5]
            step[10] += force.step[10]
            step[11] += force.step[11]

    def _locate(self, cell: int) -> tuple[int, int]:
        for k, part in enumerate(self.parts):
            where = np.flatnonzero(part.cells == cell)
            if len(where):
                return k, int(where[0])
        raise KeyError(cell)

    def steps_at_rest(self) -> np.ndarray:
        """Every owned cell's stable step estimate at rest (s), part after part."""
        return np.concatenate([force.steps_at_rest() for force in self.elements])

    @property
    def plastic_work(self) -> float:
        """Plastic dissipation (J) of this rank's cells so far."""
        return sum(force.plastic_work for force in self.elements)

    def plastic_strains(self) -> np.ndarray:
        """The equivalent plastic strain of every integration point of the plastic parts."""
        return np.concatenate(
            [f.plastic_strains().ravel() for f in self.elements if f.plastic] or [np.zeros(0)]
        )

    def part_momenta(self, state) -> np.ndarray:
        """(parts, 3): this rank's share of each part's momentum (kg m/s) at v^{n+1/2}, by
        the parts' shares of the nodes' masses."""
        return self.shares(state).T @ (state.mass[:, None] * state.v)

    def shares(self, state) -> np.ndarray:
        """(owned nodes, parts): each part's share of each node's mass."""
        return self.part_masses / state.mass[:, None]

    def part_kinetic(self, state) -> np.ndarray:
        """Each part's share of the shadow kinetic energy K^n (J, this rank), after the
        update of step n (v^{n-1/2} = v^{n+1/2} - dt^n a^n)."""
        v_old = state.v - state.dt_velocity * state.a
        per_node = 0.5 * state.mass * np.einsum("ij,ij->i", v_old, state.v)
        return per_node @ self.shares(state)

    def cell_fields(self, state) -> dict[str, np.ndarray]:
        """Values per owned cell for the outputs: the parts' cell fields (zero on the cells
        of parts without them; the plane stresses of a shell surface, (3, cells) in its
        local frame, Pa, as ``<name>_xx``, ``_yy``, ``_xy``) and, for a body of parts,
        ``"part"``, the part's index."""
        owned = self.V.mesh.topology.index_map(self.V.mesh.topology.dim).size_local
        fields: dict[str, np.ndarray] = {}
        for part, force in zip(self.parts, self.elements, strict=True):
            for name, values in force.cell_fields(state).items():
                if values.ndim == 2:
                    for component, row in zip(("xx", "yy", "xy"), values, strict=True):
                        fields.setdefault(f"{name}_{component}", np.zeros(owned))[
                            part.cells] = row  # fmt: skip
                else:
                    fields.setdefault(name, np.zeros(owned))[part.cells] = values
        if self.explicit:
            index = np.zeros(owned)
            for k, part in enumerate(self.parts):
                index[part.cells] = k
            fields["part"] = index
        return fields

    def _element_states(self) -> dict[str, np.ndarray]:
        """Each part's element force's checkpoint arrays, named ``part<k>_<name>``."""
        arrays = {}
        for k, force in enumerate(self.elements):
            arrays |= {f"part{k}_{name}": a for name, a in force.checkpoint_state().items()}
        return arrays

    def _restore_elements(self, arrays: dict[str, np.ndarray]) -> None:
        for k, force in enumerate(self.elements):
            prefix = f"part{k}_"
            mine = {n.removeprefix(prefix): a for n, a in arrays.items() if n.startswith(prefix)}
            force.restore_state(mine)


class Body(PartedBody):
    """The internal force of the body's ``parts`` (:class:`Part`) on the vector space ``V``,
    with the displacement and velocity fields ``u`` and ``v``: an effect that *sets*
    ``state.a``. ``explicit``: the scene gave its parts (the outputs report them).

    Like one :class:`~rwall_fem.elements.ElementForce` it has the node coordinates ``X``
    (m) and the owned cells' nodes ``cells``, and gives the energies of the body
    (``energy_names``, ``energy_parts``, :meth:`energies`), the cell fields over the owned
    cells, and what its kernels noted of the cells' stable steps (:attr:`step`, the cell an
    index among the owned cells; :attr:`controlling_part`). :attr:`books_work` says whether
    the update sums the work of its force (a part without a stored energy, or a step that
    varies: the simulation sets it) and hands it to :meth:`book`.
    """

    def __init__(self, V, parts: list[Part], u: GhostedField, v: GhostedField, *,
                 explicit: bool = False):  # fmt: skip
        self.V, self.u, self.v = V, u, v
        self.f = GhostedField(V)
        self.parts, self.explicit = parts, explicit
        self.elements = [  # the parts' element forces, in the order of the parts
            ElementForce(V, part.material, part.technology, u, v, cells=part.cells, f=self.f)
            for part in parts
        ]
        self.X = self.elements[0].X  # node coordinates (m), owned and ghost
        owned = V.mesh.topology.index_map(V.mesh.topology.dim).size_local
        self.cells = np.empty((owned, self.elements[0].cells.shape[1]), dtype=np.int32)
        for part, force in zip(parts, self.elements, strict=True):
            self.cells[part.cells] = force.cells  # the owned cells' nodes, local order
        self.name = (
            parts[0].material.model
            if len(parts) == 1
            else "parts: " + ", ".join(f"{part.name} {part.material.model}" for part in parts)
        )
        self.conservative = all(force.conservative for force in self.elements)
        self.plastic = any(force.plastic for force in self.elements)
        self.nodal_force = self.f.owned  # N, owned nodes
        self.books_work = not self.conservative
        # One part over all the owned cells: what its kernel notes of the steps is the body's.
        self._alone = len(parts) == 1 and np.array_equal(parts[0].cells, np.arange(owned))
        self.step = self.elements[0].step if self._alone else np.zeros(STEP_SLOTS)
        self.controlling_part = 0
        self._acceleration = None
        count = len(parts)
        self.held = held_nodes(V, self.elements)  # (owned + ghost nodes, parts): their cells'
        # Each owned node's part when that part's cells alone hold it, else -1 (an
        # interface); the rows (owned and ghost) of the interface nodes, and per part the
        # forces its cells put on them at the latest step (N).
        self.labels, self.part_sums = None, np.zeros(2 * count)
        self._shared, self._interface_force, self._interface_works = None, None, []
        if count > 1:
            self.labels = self._interfaces()
        # The books per part (J): the work of its forces (or a stored energy's correction)
        # over the finished halves, its value at the latest step, and what is pending.
        self._done = np.zeros(count)
        self._latest = np.zeros(count)
        self._interface_first = np.zeros(count)
        self._pending = None  # (dt_v, change) of the latest step: its v^{n+1/2} halves
        self.part_masses = None  # (owned nodes, parts), kg: set by the builder
        owned_nodes = V.dofmap.index_map.size_local
        self._eroded = ErodedParts(parts, self.elements, self.held[:owned_nodes], owned)
        self._name_energies()

    def _name_energies(self) -> None:
        """:attr:`energy_names`, the energies of the balance: ``"internal"``,
        ``"hourglass"`` when some part has hourglass control, ``"eroded_internal"`` when
        some part's cells may erode; :attr:`energy_parts`, those reported beside them:
        ``"elastic"`` and ``"plastic_work"`` of elasto-plastic parts, ``"eroded_kinetic"``
        (detached nodes) when cells may erode; :attr:`erosion`, the eroded cells and
        detached nodes, None when no part's cells may erode."""
        names = {name for force in self.elements for name in force.energy_names}
        parts = {name for force in self.elements for name in force.energy_parts}
        order = ("internal", "hourglass", "eroded_internal")
        self.energy_names = tuple(n for n in order if n in names)
        order = ("elastic", "plastic_work", "eroded_kinetic")
        self.energy_parts = tuple(n for n in order if n in parts)
        self.erosion = self._eroded if any(f.erosion for f in self.elements) else None

    # --- the step ----------------------------------------------------------------------

    def accelerate(self, state) -> None:
        """Set ``state.a = -f_int(u^n) / m`` on the owned nodes, every part's kernel adding
        its force; combine what they noted of the stable steps."""
        self.u.scatter_forward()
        if self.books_work or self.erosion is not None:  # the velocities of eroding cells too
            self.v.scatter_forward()
        if self.books_work:
            self._second_halves_at_interfaces()
        self.f.array.fill(0.0)
        self._begin_nodal_stiffness()
        shared = self._shared if self.books_work else None
        for k, force in enumerate(self.elements):
            if shared is not None:  # what this part adds at the interfaces
                kept = self._interface_force[k]
                np.take(self.f.array, shared, axis=0, out=self._before, mode="clip")
            force.compute(state)
            if shared is not None:
                np.take(self.f.array, shared, axis=0, out=kept, mode="clip")
                kept -= self._before
        if shared is not None:
            self._interface_first = np.array([work() for work in self._interface_works])
        self.f.scatter_reverse_add()
        self._end_nodal_stiffness()
        if not self._alone:
            self._combine_steps()
        self._acceleration = acceleration_pass(self._acceleration, self.f.array,
                                               state.inv_mass, state.a)  # fmt: skip
        self._acceleration()

    def book(self, state, first: float, second: float) -> None:
        """Book each part's work after the update of step n, from ``first`` and ``second``,
        sum f . v^{n-1/2} and sum f . v^{n+1/2} on the owned nodes (W), and per part
        :attr:`part_sums` (the nodes of one part alone) and the interface cells' forces:
        the work of step n's forces at mid-step velocities (dt^n/2 (first + second)), or
        for a stored energy the correction of a varying step ((dt^{n+1/2} - dt^{n-1/2})/4
        (first - second)); what is booked up to step n holds its first half only. The
        interfaces' v^{n+1/2} halves wait for the ghost velocities: the next step."""
        dt_v = state.dt_velocity
        change = 0.25 * (state.dt - (state.dt_previous or state.dt))
        if self.labels is None:
            firsts, seconds = np.array([first]), np.array([second])
        else:
            sums = self.part_sums.reshape(-1, 2)
            firsts, seconds = sums[:, 0] + self._interface_first, sums[:, 1]
            self._pending = (dt_v, change)
        for k, force in enumerate(self.elements):
            if force.conservative:
                self._latest[k] = self._done[k] + change * firsts[k]
                self._done[k] += change * (firsts[k] - seconds[k])
            else:
                self._latest[k] = self._done[k] + 0.5 * dt_v * firsts[k]
                self._done[k] += 0.5 * dt_v * (firsts[k] + seconds[k])

    def _second_halves_at_interfaces(self) -> None:
        """At step n + 1, the ghost velocities v^{n+1/2} scattered: the interfaces' second
        halves of step n, from the forces the kernels kept (before they overwrite them)."""
        if self._pending is None:
            return
        dt_v, change = self._pending
        self._pending = None
        for k, force in enumerate(self.elements):
            second = self._interface_works[k]()
            if force.conservative:
                self._done[k] -= change * second
            else:
                self._done[k] += 0.5 * dt_v * second

    # --- parts that share nodes --------------------------------------------------------

    def _interfaces(self) -> np.ndarray:
        """The owned nodes' labels: a part when that part's cells alone hold the node, -1
        at an interface of parts; makes room for the parts' forces at the interface nodes
        (owned and ghost rows) and the compiled sums of their work."""
        shared = (self.held > 0).sum(axis=1) > 1  # owned and ghost nodes
        self._shared = np.flatnonzero(shared).astype(np.int32)
        count, rows = len(self.elements), len(self._shared)
        self._before = np.zeros((rows, 3))
        self._interface_force = np.zeros((count, rows, 3))
        lib, ffi = self.elements[0].lib, self.elements[0].ffi
        for k in range(count):  # sum of part k's forces . v at the interface nodes (W)
            self._interface_works.append(
                functools.partial(
                    lib.interface_work,
                    rows,
                    ffi.cast("int32_t *", self._shared.ctypes.data),
                    ffi.cast("double *", self._interface_force[k].ctypes.data),  # kept, in place
                    ffi.cast("double *", self.v.array.ctypes.data),
                )
            )
        owned = self.V.dofmap.index_map.size_local
        labels = np.where(shared, -1, self.held.argmax(axis=1))[:owned]
        return np.ascontiguousarray(labels, dtype=np.int32)

    # --- energies ----------------------------------------------------------------------

    def energies(self, state) -> dict[str, float]:
        """This rank's energies (J) at step n: ``"internal"`` (the parts' strain energies,
        and the works less the hourglass energies of the parts without one),
        ``"hourglass"`` when some part has hourglass control, and for elasto-plastic
        parts ``"elastic"`` and ``"plastic_work"``, their sums over the parts."""
        each = self.part_energies(state, kinetic=False)
        if len(each) == 1:
            energies = each[0]
        else:
            energies = {n: sum(e.get(n, 0.0) for e in each) for n in self.energy_names}
            for name in self.energy_parts:
                energies[name] = sum(e.get(name, 0.0) for e in each)
        if self.erosion is not None:
            energies["eroded_kinetic"] = self._eroded.kinetic_energy(state)
        return energies

    @property
    def corrects(self) -> bool:
        """Whether some part's stored energy takes the correction of a varying step."""
        return self.books_work and any(force.conservative for force in self.elements)

    def step_change_work(self) -> float:
        """What the changes of the step put into the stored energies up to step n (J, this
        rank): minus the correction the parts with one booked."""
        return -sum(self._latest[k] for k, f in enumerate(self.elements) if f.conservative)

    def part_energies(self, state, kinetic: bool = True) -> list[dict[str, float]]:
        """Per part, this rank's energies (J) at step n: ``kinetic`` (the nodes' shadow
        kinetic energy by the part's share of their masses, if asked), ``internal``,
        ``hourglass`` (with hourglass control), ``elastic`` and ``plastic_work``
        (elasto-plastic laws)."""
        out = []
        for k, force in enumerate(self.elements):
            hourglass, eroded = force.hourglass_energy, force.eroded_energy
            if force.conservative:
                internal = force.stored_energy
            else:
                internal = self._latest[k] - hourglass - eroded
            energies = {"internal": internal}
            if force.erosion is not None:
                energies["eroded_internal"] = eroded
            if "hourglass" in force.energy_names:
                energies["hourglass"] = hourglass
            if force.plastic:
                energies |= {"elastic": force.stored_energy, "plastic_work": force.plastic_work}
            out.append(energies)
        if kinetic:
            for energies, value in zip(out, self.part_kinetic(state), strict=True):
                energies["kinetic"] = value
        return out

    def part_columns(self) -> tuple[str, ...]:
        """The per-part columns of ``energy.csv``, part after part: ``<part>.kinetic``,
        ``<part>.internal``, and ``<part>.hourglass`` and ``<part>.plastic_work`` for the
        parts that have them (:meth:`part_values` gives their values)."""
        return tuple(
            f"{part.name}.{name}"
            for part, force in zip(self.parts, self.elements, strict=True)
            for name in self._part_energy_names(force)
        )

    def part_values(self, state) -> np.ndarray:
        """This rank's values (J) of :meth:`part_columns` at step n."""
        each = self.part_energies(state)
        return np.array(
            [
                energies[name]
                for energies, force in zip(each, self.elements, strict=True)
                for name in self._part_energy_names(force)
            ]
        )

    @staticmethod
    def _part_energy_names(force) -> tuple[str, ...]:
        hourglass = ("hourglass",) if "hourglass" in force.energy_names else ()
        return ("kinetic", "internal", *hourglass, *(("plastic_work",) if force.plastic else ()))

    # --- the stable step, through the parts ---------------------------------------------

    @property
    def estimate_every_step(self) -> bool:
        return any(force.estimate_every_step for force in self.elements)

    def calibrate(self, dt_exact: float, cap: bool = True) -> float:
        """Scale every part's estimates by the exact stable step at rest ``dt_exact`` (s)
        over their smallest L / c at rest (collective), at most 1 if ``cap``; returns that
        ratio."""
        smallest = min(
            float((f.length0 / f.params.wave_speed).min(initial=np.inf)) for f in self.elements
        )
        ratio = dt_exact / self.V.mesh.comm.allreduce(smallest, op=MPI.MIN)
        for force in self.elements:
            force.params.calibration = min(1.0, ratio) if cap else ratio
        return ratio

    @property
    def calibration(self) -> float:
        return self.elements[0].params.calibration

    def cell_position(self, cell: int) -> np.ndarray:
        """The centroid (m) of the owned ``cell`` (its local index) at X + u."""
        part, local = self._locate(cell)
        return self.elements[part].cell_position(local)

    def describe_cell(self, cell: int) -> str:
        """The owned ``cell``'s part and state in words."""
        part, local = self._locate(cell)
        said = self.elements[part].describe_cell(local)
        return f"of part {self.parts[part].name}, {said}" if self.explicit else said

    def forces(self, u: np.ndarray) -> np.ndarray:
        """Internal forces (N) on the owned nodes for a displacement ``u`` (owned, (n, 3)),
        summed over the parts (elastic laws), the body's state left as it is."""
        return sum(force.forces(u) for force in self.elements)

    # --- checkpoints -------------------------------------------------------------------

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """Each part's, and the books of the parts' works."""
        arrays = {
            "books": np.concatenate([self._done, self._latest, self._interface_first]),
            "pending": np.array(self._pending if self._pending else (np.nan, np.nan)),
        }
        if self.part_masses is not None:
            arrays["part_masses"] = self.part_masses
        if self._interface_force is not None:
            arrays["interface_force"] = self._interface_force
        return arrays | self._element_states()

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        count = len(self.elements)
        books = arrays["books"]
        self._done[:], self._latest[:] = books[:count], books[count : 2 * count]
        self._interface_first[:] = books[2 * count :]
        pending = arrays["pending"].tolist()
        self._pending = None if np.isnan(pending[0]) else tuple(pending)
        if "part_masses" in arrays:
            self.part_masses[:] = arrays["part_masses"]
        if self._interface_force is not None:
            self._interface_force[...] = arrays["interface_force"]
        self._restore_elements(arrays)


def held_nodes(V, forces: list) -> np.ndarray:
    """(owned + ghost nodes, parts): how many cells of each part hold each node, on any
    rank (collective), from the parts' element forces ``forces`` (their ``cells``: rows of
    node indices of their owned cells), solid or shell."""
    count = len(forces)
    held = la.vector(V.dofmap.index_map, count)
    rows = held.array.reshape(-1, count)
    for k, force in enumerate(forces):
        np.add.at(rows[:, k], force.cells.ravel(), 1.0)
    _compat.scatter_reverse_add(held)
    held.scatter_forward()
    return rows.copy()


def part_masses(V, parts: list[Part]) -> np.ndarray:
    """(owned nodes, parts): each part's row-sum lumped masses (kg), the density of its
    material over its cells (their sum: the body's lumped mass)."""
    from dolfinx import fem

    from rwall_fem.mechanics import lumped_mass

    msh = V.mesh
    density = fem.Function(_compat.scalar_space(msh))
    owned = msh.topology.index_map(msh.topology.dim).size_local
    cell_dofs = _compat.cell_nodes(density.function_space)[:owned, 0]
    masses = []
    for part in parts:
        density.x.array[:] = 0.0
        density.x.array[cell_dofs[part.cells]] = part.material.density
        density.x.scatter_forward()
        masses.append(lumped_mass(V, density, positive=False))
    return np.column_stack(masses)


def shared_velocities(body: Body, comm) -> str | None:
    """The first pair of parts that share nodes but start at different velocities, in
    words (collective), or None."""
    owned = body.V.dofmap.index_map.size_local
    held = body.held[:owned] > 0
    for k, first in enumerate(body.parts):
        for j in range(k + 1, len(body.parts)):
            second = body.parts[j]
            if tuple(first.velocity) == tuple(second.velocity):
                continue
            shared = comm.allreduce(int(np.count_nonzero(held[:, k] & held[:, j])))
            if shared:
                return (
                    f"the parts '{first.name}' and '{second.name}' share {shared} nodes but ask "
                    f"for the initial velocities {list(first.velocity)} and "
                    f"{list(second.velocity)} m/s: bonded parts start together"
                )
    return None


def piece_overlaps(body: Body, X: np.ndarray, comm, touching=frozenset()) -> list[str]:
    """Warnings, one line each, for parts of pieces that share no node whose boxes overlap
    at the start (collective): the pieces of one body do not touch each other unless a
    contact interface names both (``touching``: pairs of part names that it does)."""
    owned = len(X)
    held = body.held[:owned] > 0
    count = len(body.parts)
    bonded = np.zeros((count, count), dtype=int)
    for k in range(count):
        for j in range(count):
            bonded[k, j] = np.count_nonzero(held[:, k] & held[:, j])
    bonded = comm.allreduce(bonded)
    piece = list(range(count))  # the pieces: parts joined through shared nodes
    for k in range(count):
        for j in range(count):
            if bonded[k, j]:
                old, new = max(piece[k], piece[j]), min(piece[k], piece[j])
                piece = [new if p == old else p for p in piece]
    boxes = []
    for k in range(count):
        x = X[held[:, k]]
        low, high = np.empty(3), np.empty(3)
        comm.Allreduce(x.min(axis=0, initial=np.inf), low, op=MPI.MIN)
        comm.Allreduce(x.max(axis=0, initial=-np.inf), high, op=MPI.MAX)
        boxes.append((low, high))
    warnings = []
    for k in range(count):
        for j in range(k + 1, count):
            names = {body.parts[k].name, body.parts[j].name}
            if piece[k] == piece[j] or any(names <= pair for pair in touching):
                continue
            (a, b), (c, d) = boxes[k], boxes[j]
            if np.all(a <= d) and np.all(c <= b):
                warnings.append(
                    f"the parts '{body.parts[k].name}' and '{body.parts[j].name}' are pieces "
                    "that share no node, and their boxes overlap at the start: pieces do not "
                    "touch each other unless a [[contact]] names both"
                )
    return warnings
