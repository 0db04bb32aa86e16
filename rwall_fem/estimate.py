"""What a scene will cost, known before meshing: cells, memory, steps and frames.

Every built-in body is a 2-D section swept along its own z (``meshes/*.geo``), so its
cell count is (cells of the section) x (layers). The section holds about one quadrangle
per h^2 where it is structured (bar, plate) and 1.3 per h^2 where gmsh meshes it freely
(round bar, plate with a hole, and any refined section); tetrahedra are about 6 per
quadrangle's place (a brick or a prism split). With a refinement the size grows
linearly from ``refine_size`` at the point to ``element_size`` at ``refine_radius``,
as ``meshes/refine.geo`` grades it, and the integral of 1/size^2 over the section
counts the cells. These factors were measured on the shapes of ``meshes/`` and hold to
about 20 %; the counts after meshing are exact and checked again.

The stable step of a mesh is about k h_min / c_p, with k = 1 for hexahedra and 0.6 for
tetrahedra (0.96 and 0.53 were measured on regular meshes): the estimate of the step is
slightly high, so the number of steps estimated is slightly low.

Memory: about 150 MB per rank, plus 1.7 kB per hexahedron or 0.8 kB per tetrahedron
(resident size of runs of 1e3 to 4e5 cells, gmsh's copy of the mesh included).

The limits (``run.max_cells``, ``run.max_steps``, ``run.max_frames``) refuse a scene
whose estimate passes them; ``rwall-fem run --lift-limits`` lifts them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rwall_fem.scene import Scene, SceneError

__all__ = [
    "LIFT_HINT",
    "Estimate",
    "estimate",
    "refuse_above_limits",
    "steps_above_limit",
    "unphysical_material",
]

LIFT_HINT = "or pass --lift-limits to rwall-fem"

_RANK_BYTES = 150e6  # resident size of a rank before the mesh, bytes
_CELL_BYTES = {"hexahedron": 1.7e3, "tetrahedron": 0.8e3,
               "quadrilateral": 1.2e3, "triangle": 1.0e3}  # per cell, bytes  # fmt: skip
# dt ~ k h_min / c_p (shells: a square's L_c is its side, a halved square's h / sqrt 2)
_STEP_FACTOR = {"hexahedron": 1.0, "tetrahedron": 0.6, "quadrilateral": 1.0, "triangle": 0.7}
_FREE_QUADS = 1.3  # quadrangles per h^2 of a section gmsh meshes freely
_TETRAHEDRA_PER_QUAD = 6.0


@dataclass(frozen=True)
class Estimate:
    """The size of a run before meshing; None where it cannot be known (a mesh file)."""

    cell: str | None  # "hexahedron" or "tetrahedron"
    cells: float | None
    memory: float | None  # bytes, all ranks together
    dt: float | None  # s
    steps: float | None
    frames: int
    fields: int

    def describe(self) -> str:
        """One line: about N cells, memory, steps of dt, frames."""
        parts = []
        if self.cells is None:
            parts.append("cells known once the mesh file is read")
        else:
            parts.append(f"about {self.cells:.3g} {self.cell} cells, {_bytes(self.memory)}")
        if self.steps is None:
            parts.append("steps known once the stable step is computed")
        else:
            parts.append(f"about {self.steps:.3g} steps of {self.dt:.3g} s")
        parts.append(f"{self.frames} frames, {self.fields} field snapshots")
        return "; ".join(parts)


def estimate(scene: Scene, ranks: int = 1) -> Estimate:
    """The cells, memory (bytes, on ``ranks`` ranks), time step (s) and steps of ``scene``."""
    out = scene.output
    mesh = scene.mesh
    if mesh is None or mesh.shape is None:
        return Estimate(None, None, None, None, None, out.frames, out.fields)
    cells = _cells(mesh)
    memory = ranks * _RANK_BYTES + cells * _CELL_BYTES[mesh.cell]
    dt = scene.run.dt
    if dt is None:
        speed = _fastest(scene)[1].material.p_wave_speed
        if not math.isfinite(speed):
            raise unphysical_material(scene, "the wave speed overflows")
        dt = scene.run.dt_scale * _STEP_FACTOR[mesh.cell] * _shortest(mesh) / speed
    steps = math.ceil(scene.run.end_time / dt - 1e-9)
    return Estimate(mesh.cell, cells, memory, dt, steps, out.frames, out.fields)


def refuse_above_limits(scene: Scene, guess: Estimate) -> None:
    """Raise a :class:`SceneError` naming the key and the way on when ``guess`` passes one
    of the scene's limits."""
    run, where = scene.run, scene.source
    if guess.cells is not None and guess.cells > run.max_cells:
        raise SceneError(
            f"{where}: run.max_cells: the mesh would have about {guess.cells:.3g} "
            f"{guess.cell} cells ({_bytes(guess.memory)}), more than run.max_cells = "
            f"{run.max_cells:g}; coarsen mesh.element_size (or refine_size), raise "
            f"run.max_cells, {LIFT_HINT}"
        )
    if guess.steps is not None:
        steps_above_limit(scene, guess.steps, guess.dt, "about ")
    for name, count in (("frames", guess.frames), ("fields", guess.fields)):
        if count > run.max_frames:
            raise SceneError(
                f"{where}: run.max_frames: output.{name} = {count} is more than run.max_frames"
                f" = {run.max_frames}; ask for fewer, raise run.max_frames, {LIFT_HINT}"
            )


def steps_above_limit(scene: Scene, steps: float, dt: float, about: str = "") -> None:
    """Raise a :class:`SceneError` when ``steps`` of ``dt`` (s) pass ``run.max_steps``."""
    run = scene.run
    if steps > run.max_steps:
        raise SceneError(
            f"{scene.source}: run.max_steps: run.end_time = {run.end_time:g} s takes "
            f"{about}{steps:.3g} steps of {dt:.3g} s, more than run.max_steps = "
            f"{run.max_steps:g}; shorten run.end_time, coarsen the mesh, raise run.max_steps, "
            f"{LIFT_HINT}"
        )


def unphysical_material(scene: Scene, reason: str) -> SceneError:
    """The error of a material whose numbers give no stable step (``reason``): a density
    or a modulus off by orders of magnitude, most often in other units than SI."""
    key, part = _fastest(scene)
    m = part.material
    return SceneError(
        f"{scene.source}: {key}: the stable time step cannot be computed ({reason}); "
        f"density = {m.density:g} kg/m^3 and young = {m.young:g} Pa give a wave speed of "
        f"{m.p_wave_speed:.3g} m/s: check their units"
    )


def _fastest(scene: Scene):
    """The key and resolved part (:attr:`~rwall_fem.scene.Scene.body_parts`) of the
    material with the fastest waves (a speed that is not a number first): the one that
    sets the step."""
    parts = scene.body_parts

    def speed(k: int) -> float:
        c = parts[k].material.p_wave_speed
        return math.inf if math.isnan(c) else c

    k = max(range(len(parts)), key=speed)
    own = scene.parts and scene.parts[k].material is not None
    return (f"part[{k}].material" if own else "material"), parts[k]


def _bytes(n: float) -> str:
    return f"about {n / 1e9:.3g} GB of memory" if n >= 1e9 else f"about {n / 1e6:.0f} MB of memory"


def _shortest(mesh) -> float:
    """The smallest cell size the mesh will have (m): element_size, refine_size, or a
    plate's layer."""
    h = min(mesh.element_size, mesh.refine_size or math.inf)
    if mesh.shape in ("plate", "plate_with_hole") and mesh.layers:
        h = min(h, mesh.size[2] / mesh.layers)
    return h


def _cells(mesh) -> float:
    """Cells of the built-in body ``mesh`` (a MeshSpec): section cells x layers."""
    h = mesh.element_size
    refine = mesh.refine_size is not None
    if mesh.shape == "tube":  # shells: the perimeter's segments x the layers along it
        side = mesh.width if mesh.section == "square" else math.pi * mesh.width / 4
        quads = 4 * math.ceil(side / h - 1e-9) * math.ceil(mesh.length / h - 1e-9)
        return quads * (2.0 if mesh.cell == "triangle" else 1.0)
    if mesh.shape == "round_bar":
        length = mesh.length
    else:
        length = mesh.size[2]
    if mesh.shape in ("bar", "plate") and not refine:
        nx, ny = (math.ceil(side / h - 1e-9) for side in mesh.size[:2])
        quads = float(nx * ny)
    else:
        quads = _FREE_QUADS * _section_integral(mesh)
    if mesh.cell in ("quadrilateral", "triangle"):  # shells: the mid-surface
        return quads * (2.0 if mesh.cell == "triangle" else 1.0)
    if mesh.shape in ("plate", "plate_with_hole"):
        layers = mesh.layers or math.ceil(length / h - 1e-9)
    elif refine:
        layers = _graded_layers(mesh, length)
    else:
        layers = math.ceil(length / h - 1e-9)
    per_quad = _TETRAHEDRA_PER_QUAD if mesh.cell == "tetrahedron" else 1.0
    return quads * layers * per_quad


def _own_point(mesh) -> np.ndarray:
    """The refinement point in the body's own frame, relative to its origin (m)."""
    from rwall_fem.meshing import rotation_to

    shift = np.asarray(mesh.refine_point, float) - np.asarray(mesh.origin, float)
    return shift @ rotation_to(mesh.axis)


def _inside_section(mesh, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Whether the points (x, y) (own frame, from the origin, m) lie in the body's section."""
    if mesh.shape == "round_bar":
        return x**2 + y**2 <= mesh.radius**2
    lx, ly = mesh.size[:2]
    inside = (x >= 0) & (x <= lx) & (y >= 0) & (y <= ly)
    if mesh.shape == "plate_with_hole":
        cx, cy = lx / 2 + mesh.hole_offset[0], ly / 2 + mesh.hole_offset[1]
        inside &= (x - cx) ** 2 + (y - cy) ** 2 >= mesh.hole_radius**2
    return inside


def _section_integral(mesh) -> float:
    """The integral of 1/size^2 over the section (about its cells per unit density).

    Polar quadrature about the refinement point (log-spaced radii, where 1/size^2 varies
    most), or about the section's centre without refinement (size h everywhere).
    """
    h = mesh.element_size
    if mesh.shape == "round_bar":
        span = 2 * mesh.radius
        centre = np.zeros(2)
    else:
        span = math.hypot(*mesh.size[:2])
        centre = np.asarray(mesh.size[:2]) / 2
    if mesh.refine_size is None:
        a, b, radius = h, 0.0, 0.0
    else:
        a, radius = mesh.refine_size, mesh.refine_radius
        b = (h - a) / radius
        centre = _own_point(mesh)[:2]
    reach = span + float(np.linalg.norm(centre))  # beyond the farthest point of the section
    r = np.geomspace(1e-2 * a, reach, 400)
    theta = np.linspace(0.0, 2 * math.pi, 181)[:-1]
    x = centre[0] + r[:, None] * np.cos(theta)
    y = centre[1] + r[:, None] * np.sin(theta)
    covered = _inside_section(mesh, x, y).mean(axis=1)  # fraction of each circle inside
    size = np.where(r < radius, a + b * r, h)
    integrand = covered * 2 * math.pi * r**2 / size**2  # dr = r dlog(r)
    return float(np.sum(0.5 * (integrand[1:] + integrand[:-1]) * np.diff(np.log(r))))


def _graded_layers(mesh, length: float) -> int:
    """Layers along a bar's sweep, graded about refine_z as ``meshes/refine.geo`` does."""
    h, a, radius = mesh.element_size, mesh.refine_size, mesh.refine_radius
    b = (h - a) / radius
    z = float(_own_point(mesh)[2])
    below = min(max(z, 0.0), length)

    def layers_within(d: float) -> float:
        if d <= radius:
            return math.log(1 + b * d / a) / b
        return math.log(h / a) / b + (d - radius) / h

    return sum(math.ceil(layers_within(d) - 1e-9) for d in (below, length - below))
