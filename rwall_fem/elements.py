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
neo-Hookean (total Lagrangian). The formulas are in ``docs/theory.md``.

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

from rwall_fem import _compat
from rwall_fem.kernels import HOURGLASS, MODELS, load

__all__ = ["ElementForce", "GhostedField", "Technology"]

CELLS = ("tetrahedron", "hexahedron")
# Default hourglass coefficient of each form: 1 reproduces full integration (physical);
# LS-DYNA's QM = 0.1 for the Flanagan-Belytschko forms.
DEFAULT_COEFFICIENT = {"physical": 1.0, "stiffness": 0.1, "viscous": 0.1, "none": 0.0}


@dataclass(frozen=True)
class Technology:
    """How the elements of a body integrate their internal force."""

    cell: str  # "tetrahedron" or "hexahedron"
    integration: str  # "full" or "reduced"
    hourglass: str = "none"  # reduced only: "physical", "stiffness", "viscous" or "none"
    hourglass_coefficient: float = 0.0  # scales the hourglass forces

    @classmethod
    def choose(
        cls, cell: str, integration=None, hourglass: str = "physical", coefficient=None
    ) -> Technology:
        """The technology for ``cell`` from a scene's ``[element]`` choices: ``integration``
        None means the default of the cell type; ``hourglass`` and ``coefficient`` (None:
        the form's default) only matter with reduced integration.

        Raises ValueError (one line, naming the key) for a combination that does not exist.
        """
        if cell not in CELLS:
            raise ValueError(f"no element technology for {cell} cells; allowed: {CELLS}")
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
            coefficient = DEFAULT_COEFFICIENT[hourglass]
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


class ElementForce:
    """Internal force f_int(u) (N) of a body, cell by cell; an effect that *sets* ``state.a``.

    ``u`` (and ``v``, read by the viscous hourglass form) are the body's displacement and
    velocity fields, shared with the :class:`~rwall_fem.solver.State`. After each
    :meth:`accelerate`, ``stored_energy`` is the elastic energy (J) of this rank's cells at
    u^n and ``hourglass_energy`` the hourglass energy: stored (physical and stiffness forms)
    or dissipated so far (viscous form).
    """

    def __init__(self, V, material, technology: Technology, u: GhostedField, v: GhostedField):
        if material.model not in MODELS:
            raise ValueError(f"no element kernel for the material model {material.model!r}")
        self.name = material.model
        self.technology = technology
        self.conservative = technology.conservative
        hourglass = technology.integration == "reduced" and technology.hourglass != "none"
        self.energy_names = ("internal", "hourglass") if hourglass else ("internal",)
        self.u, self.v = u, v
        self.f = GhostedField(V)
        self.V, self._probe = V, None  # the fields of forces(), made at its first call
        self.ffi, self.lib = ffi, lib = load()
        tdim = V.mesh.topology.dim
        num_cells = V.mesh.topology.index_map(tdim).size_local
        self.cells = np.ascontiguousarray(_compat.cell_nodes(V)[:num_cells], dtype=np.int32)
        self.X = np.ascontiguousarray(V.tabulate_dof_coordinates(), dtype=np.float64)
        self.num_cells = num_cells
        self.params = ffi.new("element_params *")
        lmbda, mu = material.lame
        self.params.lmbda, self.params.mu = lmbda, mu
        self.params.density, self.params.wave_speed = material.density, material.p_wave_speed
        self.params.hourglass_coefficient = technology.hourglass_coefficient
        self._energy = np.zeros(2)
        self.hourglass_energy = 0.0
        self._kernel = self._bind(self.u.array, self.v.array, self.f.array, self._energy)
        self._inv_mass = None
        # Without a stored energy (viscous hourglass), the update books the work of f.
        self.booked_force = None if self.conservative else self.f.owned

    def _bind(self, u: np.ndarray, v: np.ndarray, f: np.ndarray, energy: np.ndarray):
        """The kernel of the technology and material, with its arguments bound."""
        ffi, t, model = self.ffi, self.technology, self.name

        def ptr(array, kind="double *"):
            return ffi.cast(kind, array.ctypes.data)

        common = (self.num_cells, ptr(self.cells, "int32_t *"), ptr(self.X), ptr(u))
        rest = (self.params, ptr(f), ptr(energy))
        if t.integration == "reduced":
            kernel = getattr(self.lib, f"hex8r_{model}_{t.hourglass}")
            return functools.partial(kernel, *common, ptr(v), *rest)
        family = "tet4" if t.cell == "tetrahedron" else "hex8"
        return functools.partial(getattr(self.lib, f"{family}_{model}"), *common, *rest)

    @property
    def stored_energy(self) -> float:
        """Elastic energy (J) of this rank's cells at the latest force computation."""
        return float(self._energy[0])

    def energies(self, state) -> dict[str, float]:
        """This rank's energies (J) at step n: ``"internal"``, the elastic strain energy (or,
        without a stored energy, the internal work less the hourglass dissipation), and
        ``"hourglass"`` when the elements have hourglass control."""
        hourglass = self.hourglass_energy
        internal = self.stored_energy if self.conservative else state.internal_work - hourglass
        energies = {"internal": internal}
        if "hourglass" in self.energy_names:
            energies["hourglass"] = hourglass
        return energies

    def accelerate(self, state) -> None:
        """Set ``state.a = -f_int(u^n) / m`` on the owned nodes."""
        self.u.scatter_forward()
        if not self.conservative:
            self.v.scatter_forward()
            self.params.dt = state.dt
        else:
            self._energy[1] = 0.0
        self._energy[0] = 0.0
        self.f.array.fill(0.0)
        self._kernel()
        self.f.scatter_reverse_add()
        self.hourglass_energy = float(self._energy[1])
        if self._inv_mass is None:
            self._inv_mass = np.ascontiguousarray(state.inv_mass[:, 0])
            self._accelerate = functools.partial(
                self.lib.internal_acceleration,
                len(self._inv_mass),
                self.ffi.cast("double *", self.f.array.ctypes.data),
                self.ffi.cast("double *", self._inv_mass.ctypes.data),
                self.ffi.cast("double *", state.a.ctypes.data),
            )
        self._accelerate()

    def forces(self, u: np.ndarray) -> np.ndarray:
        """Internal forces (N) on the owned nodes for a displacement ``u`` (owned, (n, 3)), in
        a new array; the body's state is left as it is (the stable step, the tests).

        The viscous hourglass form contributes nothing here (it acts on velocities).
        """
        if self._probe is None:
            V = self.V
            fields, energy = (GhostedField(V), GhostedField(V), GhostedField(V)), np.zeros(2)
            self._probe = (*fields, self._bind(*(g.array for g in fields), energy), energy)
        u_probe, _, f_probe, kernel, energy = self._probe
        u_probe.owned[:] = u
        u_probe.scatter_forward()
        f_probe.array.fill(0.0)
        energy[:] = 0.0
        kernel()
        f_probe.scatter_reverse_add()
        return f_probe.owned.copy()

    def stored_energy_at(self, u: np.ndarray) -> tuple[float, float]:
        """Elastic and stored hourglass energies (J) of the whole body at a displacement
        ``u`` (owned, (n, 3)), summed over ranks; the body's state is left as it is."""
        self.forces(u)
        elastic, hourglass = self._probe[4]
        if not self.conservative:
            hourglass = 0.0
        return tuple(self.V.mesh.comm.allreduce(np.array([elastic, hourglass])))

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The energies of the latest force computation (J): the viscous hourglass form
        accumulates its dissipation in the second."""
        return {"energy": self._energy}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self._energy[:] = arrays["energy"]
        self.hourglass_energy = float(self._energy[1])
