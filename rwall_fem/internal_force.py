"""What the element families' internal forces share: the solids'
:class:`~rwall_fem.elements.ElementForce` and the shells'
:class:`~rwall_fem.shells.elements.ShellForce`.

- :func:`set_flow_stress` and :func:`set_failure` put a material's flow-stress law and
  failure criterion into the kernels' ``element_params`` (``kernels/plasticity.h``,
  ``kernels/failure.h``).
- :func:`acceleration_pass` binds the compiled pass a = -f / m to a force's arrays and a
  state's.
- :class:`InternalForce` is the part of a force over some cells that does not depend on
  the element: one kernel pass per step (:meth:`~InternalForce.compute`), the energies
  the kernels book, what they noted of the cells' stable steps (``kernels/step.h``), the
  erosion of failed cells (:mod:`rwall_fem.erosion`), the lists of mass scaling and the
  checkpoints.

DOLFINx is imported only when cells may erode: the shells' kernels also run on NumPy
arrays alone.
"""

from __future__ import annotations

import functools
import operator

import numpy as np

from rwall_fem.kernels import FAILURE, load

__all__ = ["HARDENING", "InternalForce", "acceleration_pass", "set_failure", "set_flow_stress"]

# What a pass notes of the cells (kernels/step.h), before it: the smallest estimate and its
# cell and place, then the inverted cells, the first's place, the listed and eroded cells.
_ESTIMATE_CLEARED = np.array([np.inf, -1.0, 0.0, 0.0, 0.0])
_NOTES_CLEARED = np.array([0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0])

# The flow-stress laws of the kernels (kernels/plasticity.h).
HARDENING = {"linear": 0, "power": 1, "table": 2, "johnson_cook": 3}


def set_flow_stress(p, material) -> float:
    """Set the flow-stress law of an elasto-plastic ``material`` (its hardening law, or
    Johnson-Cook's) in the kernel parameters ``p``: yield stress and hardening constants
    (Pa), rate constants, the hardening table, the heating constants. Returns the room
    temperature (K) the points start at, 0 without heating. Constants the material does
    not have are 0 (the reference rate 1/s)."""
    law = material.hardening if material.model == "elastic_plastic" else "johnson_cook"
    p.hardening = HARDENING[law]
    p.yield_stress = material.yield_stress or 0.0
    p.hardening_modulus = getattr(material, "hardening_modulus", None) or 0.0
    p.hardening_coefficient = getattr(material, "hardening_coefficient", None) or 0.0
    p.hardening_exponent = getattr(material, "hardening_exponent", None) or 0.0
    p.rate_coefficient = getattr(material, "strain_rate_coefficient", 0.0)
    p.reference_rate = getattr(material, "reference_strain_rate", 1.0)
    curve = getattr(material, "hardening_curve", None)
    if curve is not None:
        p.table_size = len(curve)
        for i, (strain, stress) in enumerate(curve):
            p.table_strain[i], p.table_stress[i] = strain, stress
    heating = getattr(material, "heating", None)
    if heating is None:
        return 0.0
    p.thermal = 1
    p.thermal_exponent = heating.softening_exponent
    p.melting_temperature = heating.melting_temperature
    p.room_temperature = heating.room_temperature
    p.specific_heat = heating.specific_heat
    p.taylor_quinney = heating.taylor_quinney
    return heating.room_temperature


def set_failure(p, failure, slot: int) -> None:
    """Set the failure criterion ``failure`` (a :class:`~rwall_fem.scene.Failure`) in the
    kernel parameters ``p``, the damage of the points kept in the state's rows from
    ``slot`` on."""
    p.failure = FAILURE[failure.criterion]
    p.damage_slot = slot
    if failure.criterion == "plastic_strain":
        p.failure_strain = failure.plastic_strain
    else:
        constants = (failure.d1, failure.d2, failure.d3, failure.d4, failure.d5)
        for i, value in enumerate(constants):
            p.damage_constants[i] = value
        p.damage_reference_rate = failure.reference_strain_rate


def acceleration_pass(bound, f: np.ndarray, inv_mass: np.ndarray, a: np.ndarray,
                      rotations: tuple | None = None):  # fmt: skip
    """The compiled pass a = -f inv_mass over the rows of ``inv_mass``
    (``internal_acceleration``: f and a (n, 3), N and m/s^2, or moments (N m) and angular
    accelerations (rad/s^2); inv_mass 1/kg or 1/(kg m^2)) on these very arrays: ``bound``
    (an earlier result, or None) when it is theirs, else the pass bound anew. It keeps the
    arrays its pointers point into, and is bound again when it is handed other ones
    (another state, or a state's array replaced) instead of writing into the old ones,
    freed or not. With ``rotations`` (moments, 1/inertias, free or None, alpha) a shell
    body's alpha = -M / I times free is set in the same sweep (``shell_acceleration``)."""
    arrays = (f, inv_mass, a) if rotations is None else (f, inv_mass, a, *rotations)
    if bound is not None and len(bound.keep) == len(arrays) and not any(
        map(operator.is_not, bound.keep, arrays)
    ):
        return bound
    if rotations is not None and len(rotations[1]) != len(inv_mass):
        raise ValueError("a shell body's rotations need an inertia per node of the state")
    ffi, lib = load()
    kernel = lib.internal_acceleration if rotations is None else lib.shell_acceleration
    pointers = (ffi.NULL if x is None else ffi.cast("double *", x.ctypes.data) for x in arrays)
    call = functools.partial(kernel, len(inv_mass), *pointers)
    call.keep = arrays  # what the pointers point into
    return call


class InternalForce:
    """The internal force of some cells of a body, computed by a compiled kernel: what
    every element family does alike.

    A subclass sets ``V`` (the function space), ``v`` (the velocity field), ``cells``
    (rows of node indices) and ``num_cells``, ``params`` (``element_params``) and ``ffi``,
    ``plastic`` (an elasto-plastic law), ``history`` (the state: rows of slots, columns of
    cells; None without one) and ``points`` (integration points per cell), ``step`` (what
    the kernels note, ``STEP_SLOTS``) and ``_energy`` (stored elastic, hourglass, plastic
    dissipation, internal energy of eroded cells: J), ``erosion`` (None until cells may
    erode), ``conservative`` and ``estimate_every_step``; :meth:`_rebind` binds its kernel
    with its arguments over the live cells to ``_kernel``.
    """

    _estimated = False  # whether a pass has estimated the cells' steps

    def _rebind(self) -> None:
        raise NotImplementedError

    def compute(self, state) -> None:
        """Add the internal force of step n of its cells into its force field (owned and
        ghost rows, before the reverse scatter); estimate the cells' stable steps and find
        the inverted cells on the way (:attr:`step`). The fields it reads must be
        scattered forward."""
        # The step just taken, dt^{n-1/2}: the elasto-plastic increment u^n - u^{n-1} is
        # dt^{n-1/2} v^{n-1/2} (0 at the first step: the state is the initial one).
        self.params.dt = state.dt_previous
        if self.conservative:
            self._energy[1] = 0.0
        self._energy[0] = 0.0
        estimate = self.estimate_every_step or not self._estimated
        self.params.estimate = estimate
        self.step[5:] = _NOTES_CLEARED
        if estimate:
            self.step[:5] = _ESTIMATE_CLEARED
            self._estimated = True
        self._kernel()
        if self.step[11]:
            self._remove_eroded()

    @property
    def energy_parts(self) -> tuple[str, ...]:
        """Parts of the energies reported beside them but not added to the balance: the
        elastic energy and plastic work of an elasto-plastic body, the kinetic energy of
        detached nodes when cells can erode."""
        parts = ("elastic", "plastic_work") if self.plastic else ()
        return parts + (("eroded_kinetic",) if self.erosion is not None else ())

    @property
    def stored_energy(self) -> float:
        """Elastic energy (J) of this rank's cells at the latest force computation."""
        return float(self._energy[0])

    @property
    def hourglass_energy(self) -> float:
        """Hourglass energy (J) of this rank's cells: stored, or the hourglass work so far."""
        return float(self._energy[1])

    @property
    def plastic_work(self) -> float:
        """Plastic dissipation (J) of this rank's cells so far."""
        return float(self._energy[2])

    @property
    def eroded_energy(self) -> float:
        """Internal energy (J) the eroded cells of this rank took with them so far."""
        return float(self._energy[3])

    @property
    def smallest_step(self) -> float:
        """The smallest stable step estimate (s) of this rank's cells at the latest force
        computation (scaled by the mass-scaling factors), inf if it has no cell."""
        return float(self.step[0])

    @property
    def inverted_cells(self) -> int:
        """How many of its cells the latest force computation found inverted."""
        return int(self.step[5])

    @property
    def damage(self) -> np.ndarray:
        """The damage D of every integration point (rows) of its cells (columns): with a
        failure criterion."""
        start = self.params.damage_slot
        return self.history[start : start + self.points]

    def list_cells_below(self, floor: float, factor: np.ndarray) -> None:
        """From now on, scale each cell's step estimate by ``factor`` (per cell, sqrt of its
        mass over its mass at rest), estimate it every step, and list the cells whose
        scaled step is below ``floor`` (s) in :attr:`below` and :attr:`below_step` (their
        steps before scaling), the first ``int(step[10])`` entries: mass scaling
        (:mod:`rwall_fem.mass_scaling`)."""
        self.estimate_every_step = True
        self.below = np.zeros(self.num_cells, dtype=np.int32)
        self.below_step = np.zeros(self.num_cells)
        self._factor = factor  # the kernels read it: mass scaling changes it in place only
        p, ffi = self.params, self.ffi
        p.step_factor = ffi.cast("double *", factor.ctypes.data)
        p.step_floor = floor
        p.below = ffi.cast("int32_t *", self.below.ctypes.data)
        p.below_step = ffi.cast("double *", self.below_step.ctypes.data)

    def note_nodal_stiffness(
        self, nodal: np.ndarray, density: float, surface: np.ndarray
    ) -> None:
        """From now on, estimate every step and add the m_c / dt_e^2 (N/m) of each cell with
        a node in ``surface`` (a bool per node row) into ``nodal`` (a row per node, owned
        and ghost; zeroed by the caller before a pass), m_c = ``density`` (kg/m^3) x its
        volume at rest / its nodes, the mass it gives each node (kg; exact for triangles,
        quadrilaterals and tetrahedra, the mean share for hexahedra): the element part of
        the nodal stable step of contact at the surface nodes."""
        self.estimate_every_step = True
        share = density * self.volume0 / self.cells.shape[1]
        self._nodal_mass = np.where(surface[self.cells].any(axis=1), share, 0.0)
        self._nodal = nodal  # what the kernels' pointer points into
        p, ffi = self.params, self.ffi
        p.nodal_mass = ffi.cast("double *", self._nodal_mass.ctypes.data)
        p.nodal_stiffness = ffi.cast("double *", nodal.ctypes.data)

    def erode_below(self, floor: float) -> None:
        """From now on, erode the cells whose step estimate falls below ``floor`` (s), and
        inverted ones (``run.dt_min_action = "erode"``; the estimates are made every step)."""
        self.estimate_every_step = True
        self.params.erode_step = floor
        if self.erosion is None:
            self._erode()
            self._rebind()

    def _erode(self) -> None:
        """Let the kernels erode cells: room for the cells they list, the work of every cell
        so far, the velocities an eroded cell needs to leave the energy books (collective)."""
        from rwall_fem.erosion import ErodedCells

        self.erosion = e = ErodedCells(self.V, self.cells)
        p, ffi = self.params, self.ffi
        p.erode = 1
        # e.listed and e.work are filled in place, a checkpoint's too; e.live is replaced and
        # bound again (_remove_eroded, restore_state)
        p.eroded = ffi.cast("int32_t *", e.listed.ctypes.data)
        p.cell_work = ffi.cast("double *", e.work.ctypes.data)
        p.cell_stride = self.num_cells
        p.velocity = ffi.cast("double *", self.v.array.ctypes.data)

    def _remove_eroded(self) -> None:
        """Compute the cells the latest pass eroded no more."""
        e = self.erosion
        e.remove(int(self.step[11]))
        self.params.live = self.ffi.cast("int32_t *", e.live.ctypes.data)
        self._rebind()

    def detach_nodes(self) -> None:
        """Count the live cells of the nodes again after a step in which some rank eroded
        cells (collective)."""
        self.erosion.detach()

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The energies of the latest force computation (J: the kernels without a stored
        energy accumulate theirs), what it noted of the cells' steps, the state of the
        cells, and which cells have eroded."""
        arrays = {"energy": self._energy, "step": self.step}
        if self.history is not None:
            arrays["history"] = self.history
        if self.erosion is not None:
            arrays |= {f"erosion_{k}": v for k, v in self.erosion.checkpoint_state().items()}
        return arrays

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self._energy[:] = arrays["energy"]
        self.step[:] = arrays["step"]
        self._estimated = True
        if self.history is not None:
            self.history[...] = arrays["history"]
        if self.erosion is not None:
            e, prefix = self.erosion, "erosion_"
            e.restore_state(
                {k.removeprefix(prefix): v for k, v in arrays.items() if k.startswith(prefix)}
            )
            live = (
                self.ffi.NULL if e.live is None else self.ffi.cast("int32_t *", e.live.ctypes.data)
            )
            self.params.live = live
            self._rebind()
