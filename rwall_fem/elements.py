"""Element technologies, and the internal force they compute cell by cell in compiled code.

Explicit codes compute the internal force element by element from the current
state, with no assembled stiffness; so does :class:`ElementForce`, through the
C kernels of :mod:`rwall_fem.kernels`. Technologies (the scene's ``[element]``):

- tetrahedra: P1, one point (exact for constant strain);
- hexahedra, ``integration = "full"``: Q1 with 2 x 2 x 2 Gauss points;
- hexahedra, ``integration = "reduced"`` (the default, as LS-DYNA's ELFORM 1 and
  Radioss's HEPH): one point with hourglass control, ``"physical"`` (assumed
  strain; on a parallelepiped exactly the fully integrated element for linear
  elasticity), ``"stiffness"`` or ``"viscous"`` (Flanagan-Belytschko), or ``"none"``.

Materials: linear elasticity (small strain), Saint Venant-Kirchhoff and
neo-Hookean (total Lagrangian), and J2 elasto-plasticity with isotropic hardening or
Johnson-Cook (hypoelastic, updated Lagrangian, with a state per integration point), which
may fail (damage per point; failed cells are eroded: :mod:`rwall_fem.erosion`).
The formulas are in ``docs/theory.md``.

MPI: each rank computes its owned cells; displacements (and velocities for the
viscous hourglass form) of ghost nodes come from their owners with
``scatter_forward``, and the forces on ghost nodes go back to their owners with
a reverse scatter that adds them.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.erosion import ErodedCells
from rwall_fem.internal_force import (
    InternalForce,
    acceleration_pass,
    set_failure,
    set_flow_stress,
)
from rwall_fem.kernels import HOURGLASS, MODELS, POINT_SLOTS, STEP_SLOTS, load

__all__ = ["ElementForce", "GhostedField", "Technology"]

CELLS = ("tetrahedron", "hexahedron")
# Default hourglass coefficient of each form: 1 reproduces full integration (physical) for
# elastic bodies; in plastic flow elastic hourglass stresses would stiffen the element
# (the Taylor rod at 1.0 ends 4 % short with a 25 % smaller mushroom), hence 0.1 there,
# LS-DYNA's default QM, also that of the Flanagan-Belytschko forms.
DEFAULT_COEFFICIENT = {"physical": 1.0, "stiffness": 0.1, "viscous": 0.1, "none": 0.0}
PLASTIC_COEFFICIENT = 0.1


@dataclass(frozen=True)
class Technology:
    """How the elements of a body integrate their internal force."""

    cell: str  # "tetrahedron" or "hexahedron"
    integration: str  # "full" or "reduced"
    hourglass: str = "none"  # reduced only: "physical", "stiffness", "viscous" or "none"
    hourglass_coefficient: float = 0.0  # scales the hourglass forces

    @classmethod
    def choose(
        cls,
        cell: str,
        integration=None,
        hourglass=None,
        coefficient=None,
        *,
        plastic: bool = False,
    ) -> Technology:
        """The technology for ``cell`` from a scene's ``[element]`` choices: ``integration``
        None means the default of the cell type; ``hourglass`` (None: "physical") and
        ``coefficient`` (None: the default of the form, and of an elasto-plastic body when
        ``plastic``) only matter with reduced integration, and may not be given for
        tetrahedra (a mesh file's cells are known only here).

        Raises ValueError (one line, naming the key) for a combination that does not exist.
        """
        if cell not in CELLS:
            raise ValueError(f"no element technology for {cell} cells; allowed: {CELLS}")
        if integration is None and cell == "tetrahedron":
            for name, value in (("hourglass", hourglass), ("hourglass_coefficient", coefficient)):
                if value is not None:
                    raise ValueError(
                        f"element.{name}: needs integration = 'reduced', and tetrahedra are "
                        "integrated 'full' (P1, one exact point): leave it out"
                    )
        hourglass = hourglass or "physical"
        if integration is None:
            integration = "reduced" if cell == "hexahedron" else "full"
        if integration == "reduced" and cell == "tetrahedron":
            raise ValueError(
                "element.integration: 'reduced' is for hexahedra; tetrahedra are one-point P1 "
                "elements: use 'full' or drop the key"
            )
        if integration == "full":
            return cls(cell, "full")
        if hourglass not in HOURGLASS:
            raise ValueError(f"element.hourglass: must be one of {HOURGLASS}, got {hourglass!r}")
        if coefficient is None:
            physical = hourglass == "physical"
            coefficient = (
                PLASTIC_COEFFICIENT if physical and plastic else DEFAULT_COEFFICIENT[hourglass]
            )
        return cls(cell, "reduced", hourglass, float(coefficient))

    @property
    def conservative(self) -> bool:
        """Whether the internal force derives from a stored energy (no viscous hourglass)."""
        return self.hourglass != "viscous"

    def describe(self) -> str:
        """E.g. 'Q1 hexahedra, one point, physical hourglass control (coefficient 1)'."""
        if self.cell == "tetrahedron":
            return "P1 tetrahedra, one point"
        if self.integration == "full":
            return "Q1 hexahedra, 2x2x2 points"
        if self.hourglass == "none":
            return "Q1 hexahedra, one point, no hourglass control"
        return (
            f"Q1 hexahedra, one point, {self.hourglass} hourglass control "
            f"(coefficient {self.hourglass_coefficient:g})"
        )


class GhostedField:
    """A nodal vector field in a DOLFINx vector: the owned nodes, then the ghosts.

    ``array`` is (owned + ghosts, 3), ``owned`` the view of its first rows.
    """

    def __init__(self, V):
        self.function = fem.Function(V)  # owns the storage: keep it alive
        self._vector = self.function.x
        self.array = self._vector.array.reshape(-1, 3)
        self.owned = self.array[: V.dofmap.index_map.size_local]
        self._parallel = V.mesh.comm.size > 1

    def scatter_forward(self) -> None:
        """Copy the owners' values into the ghost rows."""
        if self._parallel:
            self._vector.scatter_forward()

    def scatter_reverse_add(self) -> None:
        """Add the ghost rows to their owners' rows."""
        if self._parallel:
            _compat.scatter_reverse_add(self._vector)


class ElementForce(InternalForce):
    """Internal force f_int(u) (N) of one material and element technology over some cells,
    cell by cell (a part of the body, :mod:`rwall_fem.body`; all the owned cells unless
    ``cells``, their local indices, is given).

    ``u`` and ``v`` are the body's displacement and velocity fields, shared with the
    :class:`~rwall_fem.solver.State` (``v`` is read by the viscous hourglass form and by
    the elasto-plastic laws, whose strain increment over a step is dt v^{n-1/2}).
    :meth:`compute` adds the force into ``f``, a field it may share with the body's other
    parts; :meth:`accelerate` (a force alone: it owns its field) also sets ``state.a``.

    Energies (J, this rank) after each :meth:`compute`: ``stored_energy``, the elastic
    energy at u^n; ``hourglass_energy``, stored (physical and stiffness forms of elastic
    bodies) or the hourglass work so far (viscous form, elasto-plastic bodies);
    ``plastic_work``, the plastic dissipation so far. An elasto-plastic body keeps its
    stress, equivalent plastic strain and temperature per integration point in
    ``history`` (rows of slots, columns of owned cells).

    The same pass estimates each owned cell's stable step and finds the inverted ones
    (``kernels/step.h``): :attr:`step` holds what it noted, :attr:`smallest_step` the
    smallest estimate (s). The cells' volumes (m^3) and characteristic lengths (m) at rest
    are :attr:`volume0` and :attr:`length0`. A small-strain body's estimate never
    changes (its stiffness does not): it is made once, unless :attr:`estimate_every_step`.

    A material with a failure criterion accumulates damage per integration point (rows of
    ``history`` after the state of the points) and its failed cells are eroded, as are,
    after :meth:`erode_below`, the cells whose step falls below a floor; :attr:`erosion`
    (an :class:`~rwall_fem.erosion.ErodedCells`, or None when no cell can erode) keeps
    which, and the energies gain ``"eroded_internal"`` (``kernels/failure.h``).
    """

    def __init__(
        self,
        V,
        material,
        technology: Technology,
        u: GhostedField,
        v: GhostedField,
        *,
        cells: np.ndarray | None = None,
        f: GhostedField | None = None,
    ):
        model = material.model
        self.plastic = material.plastic
        if model not in MODELS and not self.plastic:
            raise ValueError(f"no element kernel for the material model {model!r}")
        self.name = model
        self.technology = technology
        self.conservative = technology.conservative and not self.plastic
        self.u, self.v = u, v
        self.f = f if f is not None else GhostedField(V)
        self.V, self._probe = V, None  # the fields of forces(), made at its first call
        self.ffi, self.lib = ffi, lib = load()
        tdim = V.mesh.topology.dim
        owned = V.mesh.topology.index_map(tdim).size_local
        # Its cells: local indices among the rank's owned cells.
        self.cell_ids = np.arange(owned, dtype=np.int32) if cells is None else np.asarray(cells)
        self.X = np.ascontiguousarray(V.tabulate_dof_coordinates(), dtype=np.float64)
        nodes = np.array(_compat.cell_nodes(V)[:owned][self.cell_ids], dtype=np.int32)
        self.cells = _oriented(nodes, self.X)
        self.num_cells = len(self.cell_ids)
        self.params = ffi.new("element_params *")
        lmbda, mu = material.lame
        self.params.lmbda, self.params.mu = lmbda, mu
        self.params.density, self.params.wave_speed = material.density, material.p_wave_speed
        self.params.hourglass_coefficient = technology.hourglass_coefficient
        self.params.calibration = 1.0
        self.points = (
            8 if technology.cell == "hexahedron" and technology.integration == "full" else 1
        )
        self.history = None
        self.failure = getattr(material, "failure", None) if self.plastic else None
        if self.plastic:
            self._set_plasticity(material)
        self.volume0, self.length0 = self.cell_sizes(self.X)
        self.params.length0 = ffi.cast("double *", self.length0.ctypes.data)
        self.params.volume0 = ffi.cast("double *", self.volume0.ctypes.data)
        self.estimate_every_step = model != "linear_elastic"
        self.step = np.zeros(STEP_SLOTS)
        # stored elastic, hourglass, plastic dissipation, internal energy of eroded cells (J)
        self._energy = np.zeros(4)
        self.erosion: ErodedCells | None = None
        self._computed: np.ndarray | None = None  # the cells computed, when some are not
        if self.failure is not None:
            self._erode()
        self._rebind()
        self._accelerate = None

    def deactivate(self, cells: np.ndarray) -> None:
        """Compute its cells ``cells`` (indices among its cells) no more, from the start: the
        cells whose nodes all move with one rigid body (:mod:`rwall_fem.rigid_body`), as
        Radioss deactivates them. Not for a force whose cells may erode (it keeps its own
        list of the cells it computes)."""
        if self.erosion is not None:
            raise ValueError("the cells of a force whose cells may erode stay computed")
        keep = np.ones(self.num_cells, dtype=bool)
        keep[cells] = False
        self._computed = np.flatnonzero(keep).astype(np.int32)
        self.params.live = self.ffi.cast("int32_t *", self._computed.ctypes.data)
        self._rebind()

    def erode_below(self, floor: float) -> None:
        if self._computed is not None:  # params.live lists the computed cells, not the live
            raise ValueError("the cells of a force with deactivated cells cannot erode")
        super().erode_below(floor)

    @property
    def energy_names(self) -> tuple[str, ...]:
        """The energies the force stores: ``"internal"``, ``"hourglass"`` with hourglass
        control, ``"eroded_internal"`` when cells can erode."""
        t = self.technology
        names = ("internal",)
        if t.integration == "reduced" and t.hourglass != "none":
            names += ("hourglass",)
        return names + (("eroded_internal",) if self.erosion is not None else ())

    def cell_sizes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The volume (m^3) and characteristic length (m) of every owned cell with its nodes
        at ``x`` (rows of owned and ghost nodes, m): V / A_max of a hexahedron, 3 V / A_max
        of a tetrahedron (``kernels/step.h``)."""
        volume, length = np.empty(self.num_cells), np.empty(self.num_cells)
        family = "tet4" if self.technology.cell == "tetrahedron" else "hex8"
        x = np.ascontiguousarray(x, dtype=np.float64)
        getattr(self.lib, f"{family}_cell_sizes")(
            self.num_cells, *(self.ffi.cast(kind, a.ctypes.data) for kind, a in (
                ("int32_t *", self.cells), ("double *", x), ("double *", volume),
                ("double *", length)))
        )  # fmt: skip
        return volume, length

    def steps_at_rest(self) -> np.ndarray:
        """Each owned cell's stable step estimate (s) at rest as the kernels make it: the
        calibration x L_0 / c_p, and with the viscous hourglass form at most
        V_0^(1/3) / (8 QM c_p) (``kernels/step.h``)."""
        c = self.params.wave_speed
        steps = self.params.calibration * self.length0 / c
        if self.technology.integration == "reduced" and self.technology.hourglass == "viscous":
            coefficient = self.params.hourglass_coefficient
            with np.errstate(divide="ignore"):
                steps = np.minimum(steps, np.cbrt(self.volume0) / (8.0 * coefficient * c))
        return steps

    def calibrate(self, dt_exact: float) -> float:
        """Scale the cells' estimates L / c by the exact stable step at rest ``dt_exact``
        (s, of the stiffness: 2 / omega_max) over their smallest at rest (collective);
        returns that ratio (the estimates follow it only up to 1)."""
        comm = self.V.mesh.comm
        smallest = float((self.length0 / self.params.wave_speed).min(initial=np.inf))
        ratio = dt_exact / comm.allreduce(smallest, op=MPI.MIN)
        self.params.calibration = min(1.0, ratio)
        return ratio

    def _set_plasticity(self, material) -> None:
        """The flow-stress law's constants, and the state per integration point: the stress
        (Pa), the equivalent plastic strain and the temperature (K) of each point, then the
        hourglass forces (N) of a one-point hexahedron, then with a failure criterion the
        damage of each point."""
        room = set_flow_stress(self.params, material)
        self.params.max_flow_stress = material.max_flow_stress or 0.0  # 0: no cap
        slots = self.points * POINT_SLOTS + (12 if self.technology.integration == "reduced" else 0)
        if self.failure is not None:  # the damage of each point, after the other slots
            set_failure(self.params, self.failure, slots)
            slots += self.points
        self.history = np.zeros((slots, self.num_cells))
        self.history[POINT_SLOTS - 1 : self.points * POINT_SLOTS : POINT_SLOTS] = room

    def _bind(self, u: np.ndarray, v: np.ndarray, f: np.ndarray, energy: np.ndarray, step):
        """The kernel of the technology and material, with its arguments bound, over the
        live cells."""
        ffi, t, model = self.ffi, self.technology, self.name

        def ptr(array, kind="double *"):
            return ffi.cast(kind, array.ctypes.data)

        if self.erosion is not None:
            computed = self.erosion.computed
        else:
            computed = self.num_cells if self._computed is None else len(self._computed)
        common = (computed, ptr(self.cells, "int32_t *"), ptr(self.X), ptr(u))
        rest = (self.params, ptr(f), ptr(energy), ptr(step))
        family = "tet4" if t.cell == "tetrahedron" else "hex8"
        if self.plastic:
            name = (
                f"hex8r_plastic_{t.hourglass}"
                if t.integration == "reduced"
                else f"{family}_plastic"
            )
            state = (ptr(self.history), self.num_cells)
            call = functools.partial(getattr(self.lib, name), *common, ptr(v), self.params, *state,
                                     ptr(f), ptr(energy), ptr(step))  # fmt: skip
        elif t.integration == "reduced":
            kernel = getattr(self.lib, f"hex8r_{model}_{t.hourglass}")
            call = functools.partial(kernel, *common, ptr(v), *rest)
        else:
            call = functools.partial(getattr(self.lib, f"{family}_{model}"), *common, *rest)
        call.keep = (self, u, v, f, energy, step)  # what the pointers point into
        return call

    def _rebind(self) -> None:
        self._kernel = self._bind(self.u.array, self.v.array, self.f.array, self._energy, self.step)

    def cell_position(self, cell: int) -> np.ndarray:
        """The centroid (m) of its ``cell`` (an index into its cells) at X + u."""
        nodes = self.cells[cell]
        return (self.X[nodes] + self.u.array[nodes]).mean(axis=0)

    def describe_cell(self, cell: int) -> str:
        """The state of its ``cell`` (an index into its cells) in words: its volume against
        its volume at rest and, when the law has them, its plastic strain and temperature."""
        volume, _ = self.cell_sizes(self.X + self.u.array)
        words = [f"volume {volume[cell] / self.volume0[cell]:.3g} of its initial"]
        if self.plastic:
            points = self.history[: self.points * POINT_SLOTS].reshape(self.points, POINT_SLOTS, -1)
            words.append(f"plastic strain {points[:, 6, cell].mean():.3g}")
            if self.params.thermal:
                words.append(f"temperature {points[:, 7, cell].mean():.4g} K")
        return ", ".join(words)

    def cell_fields(self, state) -> dict[str, np.ndarray]:
        """Values per cell of its own for the outputs: for an elasto-plastic body the equivalent
        plastic strain ``"plastic_strain"`` and the von Mises stress ``"von_mises_stress"``
        (Pa), means over its integration points, and with a failure criterion the damage
        ``"damage"``, the largest of its points' (1: failed); when cells can erode,
        ``"eroded"``, 1 for an eroded cell (its other values are those it failed with) and
        0 for a live one. Nothing for an elastic body that cannot erode."""
        fields = {}
        if self.plastic:
            points = self.history[: self.points * POINT_SLOTS]
            points = points.reshape(self.points, POINT_SLOTS, -1)
            s = points[:, :6]
            pressure = s[:, :3].mean(axis=1, keepdims=True)
            deviator = s[:, :3] - pressure
            squares = (deviator**2).sum(axis=1) + 2.0 * (s[:, 3:] ** 2).sum(axis=1)
            fields = {
                "plastic_strain": points[:, 6].mean(axis=0),
                "von_mises_stress": np.sqrt(1.5 * squares).mean(axis=0),
            }
        if self.failure is not None:
            fields["damage"] = self.damage.max(axis=0)
        if self.erosion is not None:
            fields["eroded"] = (~self.erosion.alive).astype(float)
        return fields

    def plastic_strains(self) -> np.ndarray:
        """The equivalent plastic strain of every integration point of the owned cells."""
        return self.history[POINT_SLOTS - 2 : self.points * POINT_SLOTS : POINT_SLOTS]

    def accelerate(self, state) -> None:
        """A force alone: set ``state.a = -f_int(u^n) / m`` on the owned nodes."""
        self.u.scatter_forward()
        if not self.conservative or self.erosion is not None:
            self.v.scatter_forward()
        self.f.array.fill(0.0)
        self.compute(state)
        self.f.scatter_reverse_add()
        self._accelerate = acceleration_pass(self._accelerate, self.f.array, state.inv_mass,
                                             state.a)  # fmt: skip
        self._accelerate()

    def forces(self, u: np.ndarray) -> np.ndarray:
        """Internal forces (N) on the owned nodes for a displacement ``u`` (owned, (n, 3)), in
        a new array; the body's state is left as it is (the stable step, the tests).

        The viscous hourglass form contributes nothing here (it acts on velocities); an
        elasto-plastic force has no such function of u alone.
        """
        if self.plastic:
            raise TypeError("an elasto-plastic force depends on the path, not on u alone")
        if self.erosion is not None:
            computed = self.erosion.computed
        else:
            computed = self.num_cells if self._computed is None else len(self._computed)
        if self._probe is None or self._probe[5] != computed:
            V = self.V
            fields = (GhostedField(V), GhostedField(V), GhostedField(V))
            energy, step = np.zeros(4), np.zeros(STEP_SLOTS)
            kernel = self._bind(*(g.array for g in fields), energy, step)
            self._probe = (*fields, kernel, energy, computed)
        u_probe, _, f_probe, kernel, energy, _ = self._probe
        u_probe.owned[:] = u
        u_probe.scatter_forward()
        f_probe.array.fill(0.0)
        energy[:] = 0.0
        estimate, self.params.estimate = self.params.estimate, False
        erode, self.params.erode = self.params.erode, 0
        kernel()
        self.params.estimate, self.params.erode = estimate, erode
        f_probe.scatter_reverse_add()
        return f_probe.owned.copy()

    def stored_energy_at(self, u: np.ndarray) -> tuple[float, float]:
        """Elastic and stored hourglass energies (J) of the whole body at a displacement
        ``u`` (owned, (n, 3)), summed over ranks; the body's state is left as it is."""
        self.forces(u)
        elastic, hourglass = self._probe[4][:2]
        if not self.conservative:
            hourglass = 0.0
        return tuple(self.V.mesh.comm.allreduce(np.array([elastic, hourglass])))


# Node permutations that turn a cell inside out: a mirror of its reference cell.
_MIRROR = {4: [0, 2, 1, 3], 8: [1, 0, 3, 2, 5, 4, 7, 6]}


def _oriented(cells: np.ndarray, X: np.ndarray) -> np.ndarray:
    """The cells (rows of node indices, DOLFINx numbering) with the mirrored ones turned so
    that every cell has a positive volume in the reference configuration ``X`` (m): the
    elasto-plastic kernels then know a cell with a non-positive volume is inverted."""
    x = X[cells]
    if cells.shape[1] == 4:
        det = np.einsum(
            "ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0])
        )
    else:  # the Jacobian at the centre of the trilinear map
        signs = np.array([[2 * (node >> k & 1) - 1 for node in range(8)] for k in range(3)])
        e = np.einsum("kI,cIi->cki", signs, x)
        det = np.einsum("ci,ci->c", e[:, 0], np.cross(e[:, 1], e[:, 2]))
    mirrored = det < 0.0
    cells[mirrored] = cells[mirrored][:, _MIRROR[cells.shape[1]]]
    return np.ascontiguousarray(cells)
