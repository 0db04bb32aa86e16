"""Shell elements: the internal force and moment of thin-walled bodies, cell by cell in
compiled code.

The kernels are ``rwall_fem/kernels/shell_quad.c`` (the Belytschko-Lin-Tsay quadrilateral,
with the Belytschko-Wong-Chiang warping correction by rigid-body projection unless the
formulation is plain ``"bt"``), ``shell_tria.c`` (the C0 triangle of Belytschko, Stolarski
and Carpenter, its transverse shear tied along its sides) and ``shell.h`` (the
plane-stress J2 return and the rule through the thickness); their formulas are in their
header comments. They are compiled through cffi into a module of their own by
:func:`rwall_fem.kernels.load` (they include its ``batch.h``, ``plasticity.h``, ``step.h``
and ``failure.h``).

:class:`ShellKernel` is the compiled kernel of one material and technology on NumPy arrays
(what the element tests drive); :class:`ShellForce` is the internal force of the cells of a
DOLFINx surface mesh, shaped like :class:`~rwall_fem.elements.ElementForce`.

Nodes have 6 degrees of freedom: translations, and rotations whose angular velocities
(rad/s, global frame) the kernels read; they write the internal force (N) and moment
(N m) of each node. The elements have no drilling stiffness (no moment about their normal)
unless :attr:`ShellTechnology.drilling_stiffness` gives the quadrilaterals drilling springs.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from rwall_fem import kernels
from rwall_fem.internal_force import InternalForce, set_failure, set_flow_stress
from rwall_fem.kernels import STEP_SLOTS

__all__ = ["ShellForce", "ShellKernel", "ShellTechnology", "load", "thickness_rule"]

SOURCES = ("batch.h", "materials.h", "plasticity.h", "step.h", "failure.h", "shell.h",
           "shell_quad.c", "shell_tria.c")  # fmt: skip
POINT_SLOTS = 5  # per point through the thickness: sxx, syy, sxy, eps_p, temperature
MAX_POINTS = 10
# "qeph": Radioss's QEPH (Ishell 24): BWC's warping correction with QEPH's physical
# hourglass stiffness per mode (shell_quad.c, quad_hourglass_qeph)
FORMULATIONS = {"quadrilateral": ("bwc", "bt", "qeph"), "triangle": ("bsc",)}
FAMILY = {"quadrilateral": "quad", "triangle": "tria"}
# The quadrilaterals' characteristic lengths of the step: "bt", Radioss's for its
# Belytschko-Tsay shells (CDLEN3); "qeph", QEPH's (CZCORC1) with its default numerical
# damping dn = QEPH_DN (the length times sqrt(1 + dn^2) - dn, cndt3.F).
STEP_LENGTHS = ("bt", "qeph")
QEPH_DN = 0.015
# DOLFINx's quadrilateral vertices (0,0), (1,0), (0,1), (1,1): counter-clockwise order.
_CCW = [0, 1, 3, 2]

_CDEF = (
    kernels.ELEMENT_PARAMS
    + """
typedef struct {
  const double *thickness;
  int points;
  double zeta[10], weight[10];
  double young, poisson, shear_factor, bar_speed;
  double hm, hf, hr;
  double fail_fraction;
  int warping, omit_energy;
  double hk;
  int hourglass_slot;
  double kd;
  int drill_slot;
  double *new_thickness;
  int qeph_step;
  double qeph_dn;
  int qeph_hourglass;
  int qeph_physical;
} shell_params;
"""
    + "".join(
        f"void shell_{family}_{law}(int64_t n, const int32_t *cells, const double *X,"
        " const double *u, const double *v, const double *w, const element_params *p,"
        " const shell_params *s, double *state, int64_t stride, double *f, double *m,"
        " double *energy, double *step);\n"
        for family in ("quad", "tria")
        for law in ("elastic", "plastic")
    )
    + "".join(
        f"void shell_{family}_sizes(const shell_params *s, int64_t n, const int32_t *cells,"
        " const double *x, double *area, double *length);\n"
        for family in ("quad", "tria")
    )
    + """
double shell_point(const element_params *p, const shell_params *s, double sigma[3],
                   double *eps_p, double *T, const double de[3]);
"""
)
SHELLS = kernels.Extension("_rwall_shells", SOURCES, _CDEF, "the shell kernels")


def load():
    """The compiled shell kernels ``(ffi, lib)``, through :func:`rwall_fem.kernels.load`
    (the same cache, checks and flags as the solids')."""
    return kernels.load(SHELLS)


def thickness_rule(points: int) -> tuple[np.ndarray, np.ndarray]:
    """Heights (over the thickness t) and weights (summing to 1) of ``points`` integration
    points through the thickness: Radioss's rule, equally spaced from the bottom surface to
    the top one with trapezoidal weights, the heights scaled by
    s = (1 / (12 sum w zeta^2))^(1/2) so that the elastic bending stiffness is exactly
    E t^3 / 12 (the plain trapezoidal rule overestimates it by 12.5 % with 5 points) while
    the membrane and bending resultants stay the work conjugates of the points' strains.
    One point: membrane only."""
    if not 1 <= points <= MAX_POINTS:
        raise ValueError(f"element.points: must be 1 to {MAX_POINTS}, got {points}")
    if points == 1:
        return np.zeros(1), np.ones(1)
    zeta = np.linspace(-0.5, 0.5, points)
    weight = np.full(points, 1.0 / (points - 1))
    weight[[0, -1]] *= 0.5
    return zeta * math.sqrt(1.0 / (12.0 * weight @ zeta**2)), weight


@dataclass(frozen=True)
class ShellTechnology:
    """How the shell elements of a body integrate their internal force."""

    cell: str  # "quadrilateral" or "triangle"
    formulation: str = "bwc"  # "bwc": BLT with the warping correction; "bt": plain BLT;
    # "bsc": the Belytschko-Stolarski-Carpenter triangle
    points: int = 5  # through the thickness (elasto-plastic laws)
    hourglass: tuple[float, float, float] = (0.01, 0.01, 0.01)  # hm, hf, hr
    shear_factor: float = 5.0 / 6.0
    # elastic hourglass stiffness (quadrilaterals; 0: viscous only, shell_quad.c)
    hourglass_stiffness: float = 0.0
    # drilling stiffness over G t A (quadrilaterals; 0: none, shell_quad.c)
    drilling_stiffness: float = 0.0
    # the characteristic length of the step (quadrilaterals, STEP_LENGTHS; shell_quad.c)
    step_length: str = "bt"
    # QEPH's yielding elastic hourglass forces (quadrilaterals with hourglass_stiffness,
    # elasto-plastic laws; shell_quad.c, qeph_hourglass_yield)
    hourglass_yield: bool = False

    @classmethod
    def choose(cls, cell: str, formulation=None, points: int = 5,
               hourglass=(0.01, 0.01, 0.01), shear_factor: float = 5.0 / 6.0,
               hourglass_stiffness: float = 0.0,
               drilling_stiffness: float = 0.0, step_length: str = "bt",
               hourglass_yield: bool = False) -> ShellTechnology:
        """The technology for ``cell`` from a scene's ``[element]`` choices; ValueError (one
        line, naming the key) for a combination that does not exist."""  # fmt: skip
        if cell not in FORMULATIONS:
            raise ValueError(
                f"no shell element for {cell} cells; allowed: quadrilateral, triangle"
            )
        allowed = FORMULATIONS[cell]
        formulation = formulation or allowed[0]
        if formulation not in allowed:
            raise ValueError(
                f"element.formulation: {formulation!r} is not for {cell} cells; allowed: {allowed}"
            )
        thickness_rule(points)
        hm, hf, hr = (float(c) for c in hourglass)
        if min(hm, hf, hr) < 0.0:
            raise ValueError("element.hourglass_coefficients: must be >= 0")
        if not 0.0 < shear_factor <= 1.0:
            raise ValueError(f"element.shear_factor: must be in (0, 1], got {shear_factor}")
        if not hourglass_stiffness >= 0.0:
            raise ValueError(
                f"element.hourglass_stiffness: must be >= 0, got {hourglass_stiffness}"
            )
        if not drilling_stiffness >= 0.0:
            raise ValueError(
                f"element.drilling_stiffness: must be >= 0, got {drilling_stiffness}"
            )
        if formulation == "qeph" and hourglass_stiffness > 0.0:
            raise ValueError(
                "element.hourglass_stiffness: not with formulation = \"qeph\" "
                "(QEPH's hourglass stiffness is its own)"
            )
        if step_length not in STEP_LENGTHS:
            raise ValueError(f"element.step_length: {step_length!r}; allowed: {STEP_LENGTHS}")
        quad = cell == "quadrilateral"
        return cls(cell, formulation, int(points), (hm, hf, hr), float(shear_factor),
                   float(hourglass_stiffness) if quad else 0.0,
                   float(drilling_stiffness) if quad else 0.0,
                   step_length if quad else "bt",
                   bool(hourglass_yield) and quad)  # fmt: skip

    def describe(self) -> str:
        """E.g. 'Belytschko-Lin-Tsay quadrilaterals with the BWC warping correction, ...'."""
        if self.cell == "triangle":
            return "Belytschko-Stolarski-Carpenter C0 triangles"
        name = "Belytschko-Lin-Tsay quadrilaterals"
        warp = " with the BWC warping correction" if self.formulation != "bt" else ""
        warp += ", QEPH's physical hourglass stiffness" if self.formulation == "qeph" else ""
        hm, hf, hr = self.hourglass
        step = ", QEPH's step length" if self.step_length == "qeph" else ""
        step += ", QEPH's yielding hourglass forces" if self.hourglass_yield else ""
        return f"{name}{warp}, viscous hourglass hm {hm:g} hf {hf:g} hr {hr:g}{step}"


class ShellKernel:
    """The compiled kernel of one material and shell technology on NumPy arrays.

    ``cells``: (n, 4) int32 rows of node indices, counter-clockwise, or (n, 3) for triangles
    (the technology's cell); ``thickness``: per cell
    (m). :attr:`history` is the state (rows of ``shell_quad.c``, columns of cells);
    :meth:`run` adds the internal forces and moments of the cells into ``f`` and ``m``.
    ``material`` needs ``young``, ``poisson``, ``density`` and, elasto-plastic (``plastic``),
    the hardening constants of :class:`rwall_fem.scene.Material`; ``max_flow_stress`` (Pa)
    caps the flow stress (inf: no cap), ``failed_share`` is the share of a cell's points that
    must fail for the cell to fail (1: all); ``thickness_change``: the kernels update
    :attr:`thickness` from the membrane strain (Radioss's Ithick = 1, ``shell.h``).
    """

    def __init__(
        self,
        material,
        technology: ShellTechnology,
        cells: np.ndarray,
        thickness,
        *,
        max_flow_stress: float = math.inf,
        failed_share: float = 1.0,
        thickness_change: bool = False,
    ):
        if not material.plastic and material.model != "linear_elastic":
            raise ValueError(
                f"material.model: {material.model!r} has no shell kernel; shells take "
                "linear_elastic, elastic_plastic or johnson_cook"
            )
        self.ffi, self.lib = ffi, lib = load()
        self.technology = technology
        self.plastic = bool(material.plastic)
        self.cells = np.ascontiguousarray(cells, dtype=np.int32)
        n = self.num_cells = len(self.cells)
        self.thickness = np.array(np.broadcast_to(thickness, (n,)), dtype=np.float64)  # own copy
        if not np.all(self.thickness > 0.0):
            raise ValueError("element.thickness: must be > 0")
        E, nu, rho = float(material.young), float(material.poisson), float(material.density)
        self.params = p = ffi.new("element_params *")
        p.lmbda, p.mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
        p.density = rho
        p.wave_speed = math.sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)))
        p.calibration = 1.0
        if not max_flow_stress > 0.0:
            raise ValueError(f"material.max_flow_stress: must be > 0, got {max_flow_stress}")
        p.max_flow_stress = max_flow_stress if max_flow_stress < math.inf else 0.0  # 0: none
        self.shell = s = ffi.new("shell_params *")
        s.thickness = ffi.cast("double *", self.thickness.ctypes.data)
        s.young, s.poisson, s.shear_factor = E, nu, technology.shear_factor
        # Radioss's shell sound speed (PM(27) = sqrt(E / rho), the engine's CDT3 and CNDT3):
        # the step L_c / c is sqrt(1 - nu^2) times longer than with the plate speed.
        s.bar_speed = math.sqrt(E / rho)
        s.hm, s.hf, s.hr = technology.hourglass
        s.warping = int(technology.formulation in ("bwc", "qeph"))
        s.qeph_physical = int(technology.formulation == "qeph")
        if not 0.0 < failed_share <= 1.0:
            raise ValueError(f"element.failed_share: must be in (0, 1], got {failed_share}")
        s.fail_fraction = failed_share
        self.failure = getattr(material, "failure", None) if self.plastic else None
        if self.plastic:
            s.points = technology.points
            zeta, weight = thickness_rule(technology.points)
            for k in range(technology.points):
                s.zeta[k], s.weight[k] = zeta[k], weight[k]
            self._set_plasticity(material)
        else:
            s.points = 0
            self.history = np.zeros((8, n))
        s.hk = technology.hourglass_stiffness
        s.qeph_step, s.qeph_dn = int(technology.step_length == "qeph"), QEPH_DN
        s.qeph_hourglass = int(technology.hourglass_yield)
        self.thickness_change = bool(thickness_change)
        if self.thickness_change:
            s.new_thickness = ffi.cast("double *", self.thickness.ctypes.data)
        if s.hk > 0.0 or s.qeph_physical:  # the elastic hourglass forces (QEPH's 12
            # hourglass stresses), in rows after the others
            s.hourglass_slot = len(self.history)
            rows = 12 if s.qeph_physical else 5
            self.history = np.concatenate([self.history, np.zeros((rows, n))])
        s.kd = technology.drilling_stiffness
        if s.kd > 0.0:  # the nodal drilling moments, in rows after the others
            s.drill_slot = len(self.history)
            self.history = np.concatenate([self.history, np.zeros((4, n))])
        self.family = FAMILY[technology.cell]
        law = "plastic" if self.plastic else "elastic"
        self.name = f"shell_{self.family}_{law}"

    @property
    def points(self) -> int:
        return int(self.shell.points)

    def _set_plasticity(self, material) -> None:
        """The flow-stress law's constants, and the state: two rows of transverse shear
        forces, then per point through the thickness its plane stress (Pa), plastic strain
        and temperature (K), then with a failure criterion the damage of each point."""
        room = set_flow_stress(self.params, material)
        points = self.points
        slots = 2 + POINT_SLOTS * points
        if self.failure is not None:
            set_failure(self.params, self.failure, slots)
            slots += points
        self.history = np.zeros((slots, self.num_cells))
        self.history[2 + POINT_SLOTS - 1 : 2 + POINT_SLOTS * points : POINT_SLOTS] = room

    def bind(self, computed: int, X, u, v, w, f, m, energy, step):
        """The kernel with its arguments bound (arrays of rows of nodes, (k, 3) float64,
        contiguous; energy (4,), step (STEP_SLOTS,)) over the first ``computed`` cells (or
        the live ones, ``params.live``)."""
        ffi = self.ffi

        def ptr(array, kind="double *"):
            return ffi.cast(kind, array.ctypes.data)

        call = functools.partial(
            getattr(self.lib, self.name), computed, ptr(self.cells, "int32_t *"), ptr(X), ptr(u),
            ptr(v), ptr(w), self.params, self.shell, ptr(self.history), self.num_cells, ptr(f),
            ptr(m), ptr(energy), ptr(step),
        )  # fmt: skip
        call.keep = (self, X, u, v, w, f, m, energy, step)  # what the pointers point into
        return call

    def run(self, dt: float, X, u, v, w, f, m, energy=None, step=None, estimate=True):
        """One pass over all cells with the step just taken ``dt`` (s): adds into f, m;
        returns (energy, step) (fresh arrays unless given)."""
        energy = np.zeros(4) if energy is None else energy
        if step is None:
            step = np.zeros(STEP_SLOTS)
            step[:2] = (np.inf, -1.0)
        self.params.dt = dt
        self.params.estimate = int(estimate)
        arrays = [np.ascontiguousarray(a, dtype=np.float64) for a in (X, u, v, w)]
        self.bind(self.num_cells, *arrays, f, m, energy, step)()
        return energy, step

    def sizes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The (projected) area (m^2) and characteristic length (m) of every cell at ``x``."""
        area, length = np.empty(self.num_cells), np.empty(self.num_cells)
        x = np.ascontiguousarray(x, dtype=np.float64)
        ffi = self.ffi
        getattr(self.lib, f"shell_{self.family}_sizes")(
            self.shell, self.num_cells, ffi.cast("int32_t *", self.cells.ctypes.data),
            ffi.cast("double *", x.ctypes.data), ffi.cast("double *", area.ctypes.data),
            ffi.cast("double *", length.ctypes.data),
        )  # fmt: skip
        return area, length

    def resultants(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """N (3, cells; N/m), M (3, cells; N) in the local frames, Q (2, cells; N/m)."""
        h = self.history
        if not self.plastic:
            return h[0:3].copy(), h[3:6].copy(), h[6:8].copy()
        zeta, weight = thickness_rule(self.points)
        t = self.thickness
        sig = self.point_stresses()  # (points, 3, cells)
        N = t * np.einsum("k,kic->ic", weight, sig)
        M = t**2 * np.einsum("k,kic->ic", weight * zeta, sig)
        return N, M, h[0:2].copy()

    def point_stresses(self) -> np.ndarray:
        """The stresses (xx, yy, xy; Pa) of every point (bottom to top), (points, 3, cells);
        for elastic cells the bottom, middle and top surfaces' N / t -+ 6 M / t^2."""
        if self.plastic:
            rows = self.history[2 : 2 + POINT_SLOTS * self.points]
            return rows.reshape(self.points, POINT_SLOTS, -1)[:, :3].copy()
        N, M = self.history[0:3], self.history[3:6]
        t = self.thickness
        return np.stack([N / t - 6 * M / t**2, N / t, N / t + 6 * M / t**2])

    def plastic_strains(self) -> np.ndarray:
        """The plastic strain of every point (points, cells)."""
        rows = self.history[2 : 2 + POINT_SLOTS * self.points]
        return rows.reshape(self.points, POINT_SLOTS, -1)[:, 3].copy()

    def point(self, sigma, eps_p: float, temperature: float, de, dt: float = 0.0):
        """The plane-stress update of one point (shell.h): returns (sigma, eps_p, T,
        dissipation density) after the strain increment de = (xx, yy, gamma_xy)."""
        ffi = self.ffi
        s = ffi.new("double[3]", list(sigma))
        e, T = ffi.new("double *", eps_p), ffi.new("double *", temperature)
        self.params.dt = dt
        dissipation = self.lib.shell_point(self.params, self.shell, s, e, T,
                                           ffi.new("double[3]", list(de)))  # fmt: skip
        return np.array(list(s)), e[0], T[0], dissipation


def von_mises(stress: np.ndarray) -> np.ndarray:
    """The von Mises stress (Pa) of plane stresses (xx, yy, xy) along axis -2."""
    sxx, syy, sxy = stress[..., 0, :], stress[..., 1, :], stress[..., 2, :]
    return np.sqrt(sxx**2 + syy**2 - sxx * syy + 3 * sxy**2)


class ShellForce(InternalForce):
    """Internal force (N) and moment (N m) of shell cells of a DOLFINx surface mesh (a part
    of the body: all owned cells unless ``cells``, their local indices), shaped like
    :class:`~rwall_fem.elements.ElementForce`.

    ``u``, ``v``, ``w`` are :class:`~rwall_fem.elements.GhostedField` of the nodes'
    displacement, velocity and angular velocity (rad/s, global); :meth:`compute` adds the
    force into ``f`` and the moment into ``m`` (owned and ghost rows; the reverse scatter
    and the accelerations are the body's). The force is that of a rate form (not
    conservative): the body books its work. Energies (J, this rank) after each
    :meth:`compute`: :attr:`stored_energy` (elastic, at step n), :attr:`hourglass_energy`
    and :attr:`plastic_work` (so far), :attr:`eroded_energy`.
    """

    conservative = False
    estimate_every_step = True  # the frame and the lengths follow the shell every cycle

    def __init__(self, V, material, technology: ShellTechnology, u, v, w, *, thickness,
                 cells=None, f=None, m=None, max_flow_stress: float = math.inf,
                 failed_share: float = 1.0, thickness_change: bool = False):  # fmt: skip
        from rwall_fem import _compat
        from rwall_fem.elements import GhostedField

        self.V, self.technology = V, technology
        self.u, self.v, self.w = u, v, w
        self.f = f if f is not None else GhostedField(V)
        self.m = m if m is not None else GhostedField(V)
        tdim = V.mesh.topology.dim
        owned = V.mesh.topology.index_map(tdim).size_local
        self.cell_ids = np.arange(owned, dtype=np.int32) if cells is None else np.asarray(cells)
        self.X = np.ascontiguousarray(V.tabulate_dof_coordinates(), dtype=np.float64)
        nodes = np.asarray(_compat.cell_nodes(V)[:owned][self.cell_ids], dtype=np.int32)
        if nodes.shape[1] != {"quadrilateral": 4, "triangle": 3}[technology.cell]:
            raise ValueError(f"element.formulation: {technology.formulation!r} is not for "
                             f"cells of {nodes.shape[1]} nodes")  # fmt: skip
        if nodes.shape[1] == 4:
            nodes = nodes[:, _CCW]
        thickness = np.broadcast_to(np.asarray(thickness, dtype=np.float64), (owned,))
        thickness = thickness[self.cell_ids] if cells is not None else thickness
        self.kernel = k = ShellKernel(
            material, technology, nodes, thickness, max_flow_stress=max_flow_stress,
            failed_share=failed_share, thickness_change=thickness_change,
        )  # fmt: skip
        self.plastic, self.failure = k.plastic, k.failure
        self.params, self.ffi = k.params, k.ffi
        self.cells, self.num_cells = k.cells, k.num_cells
        self.history = k.history
        self.points = k.points
        self.area0, self.length0 = k.sizes(self.X)
        self.volume0 = self.area0 * k.thickness  # m^3, at rest
        self.step = np.zeros(STEP_SLOTS)
        self._energy = np.zeros(4)
        self.erosion = None
        if self.failure is not None:
            self._erode()
        self._rebind()

    @property
    def energy_names(self) -> tuple[str, ...]:
        names = ("internal",)
        t = self.technology
        if t.cell == "quadrilateral" and any(c > 0.0 for c in t.hourglass):
            names += ("hourglass",)
        return names + (("eroded_internal",) if self.erosion is not None else ())

    def _rebind(self) -> None:
        computed = self.num_cells if self.erosion is None else self.erosion.computed
        self._kernel = self.kernel.bind(computed, self.X, self.u.array, self.v.array,
                                        self.w.array, self.f.array, self.m.array, self._energy,
                                        self.step)  # fmt: skip

    def steps_at_rest(self) -> np.ndarray:
        """Each owned cell's stable step estimate at rest (s): calibration x L_c / c_bar."""
        return self.params.calibration * self.length0 / self.kernel.shell.bar_speed

    def plastic_strains(self) -> np.ndarray:
        """The equivalent plastic strain of every point through the thickness (rows, bottom
        to top) of its cells (columns); elasto-plastic forces only."""
        return self.kernel.plastic_strains()

    def cell_fields(self, state) -> dict[str, np.ndarray]:
        """Per owned cell: ``stress_bottom``, ``stress_middle``, ``stress_top`` ((3, cells):
        xx, yy, xy in the cell's local frame, Pa; of the outermost and middle points for
        elasto-plastic cells, the surfaces' for elastic ones), ``von_mises_stress`` (the
        largest of the three), and elasto-plastic ``plastic_strain`` (the largest of the
        points'), ``damage`` (the largest), ``eroded``; ``thickness`` (m) when it changes."""
        sig = self.kernel.point_stresses()
        surfaces = sig[[0, len(sig) // 2, -1]]
        fields = {
            "stress_bottom": surfaces[0],
            "stress_middle": surfaces[1],
            "stress_top": surfaces[2],
            "von_mises_stress": von_mises(surfaces).max(axis=0),
        }
        if self.plastic:
            fields["plastic_strain"] = self.kernel.plastic_strains().max(axis=0)
        if self.failure is not None:
            fields["damage"] = self.damage.max(axis=0)
        if self.kernel.thickness_change:
            fields["thickness"] = self.kernel.thickness.copy()
        if self.erosion is not None:
            fields["eroded"] = (~self.erosion.alive).astype(float)
        return fields

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        arrays = super().checkpoint_state()
        if self.kernel.thickness_change:
            arrays["thickness"] = self.kernel.thickness
        return arrays

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        if self.kernel.thickness_change:
            self.kernel.thickness[:] = arrays["thickness"]
        super().restore_state(arrays)
