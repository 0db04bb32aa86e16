"""From a validated scene to a ready-to-run :class:`~rwall_fem.solver.Simulation`.

Data flows one way: scene -> body (mesh, space, lumped mass, element technology) -> stable
time step -> pipeline (internal force, body forces, walls, boundary conditions: only what
the scene asks for) -> recorders (history, stable-step monitor, fields, frames).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.boundary import VelocityBoundary
from rwall_fem.effects import Gravity
from rwall_fem.elements import ElementForce, GhostedField, Technology
from rwall_fem.mechanics import critical_time_step, element_time_step, lumped_mass
from rwall_fem.meshing import (
    BodyMesh,
    body_mesh,
    boundary_nodes,
    coordinate_noise,
    group_nodes,
    perturb,
)
from rwall_fem.output.guards import Guards
from rwall_fem.output.history import History
from rwall_fem.scene import SHAPE_KEYS, Scene, SceneError, WallSpec, load_scene
from rwall_fem.solver import Simulation, State
from rwall_fem.walls import RigidWall
from rwall_fem.walls.motion import MainNodeMotion, PrescribedMotion
from rwall_fem.walls.shapes import SHAPES

__all__ = ["build_simulation", "run_scene"]

log = logging.getLogger("rwall_fem")


def run_scene(
    scene: Scene | str | Path,
    out: str | Path | None = None,
    overrides=(),
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> dict:
    """Build and run a scene (object or TOML path); returns the summary written to ``out``."""
    if not isinstance(scene, Scene):
        scene = load_scene(scene, list(overrides))
    sim = build_simulation(scene, comm, out)
    sim.run()
    return sim.history.summary


def build_simulation(
    scene: Scene,
    comm: MPI.Comm = MPI.COMM_WORLD,
    out: str | Path | None = None,
    *,
    body: BodyMesh | None = None,
) -> Simulation:
    """Mesh the body, lump its mass, choose dt and assemble the pipeline.

    ``body`` is a mesh of your own (``BodyMesh(msh, facet_tags, groups)``, any
    distributed DOLFINx mesh of tetrahedra or hexahedra); it replaces the
    scene's ``[mesh]`` and sets the communicator. Outputs go to ``out``, by default
    the scene's ``output.directory``.
    """
    solid = _solid(scene, comm, body)
    dt = _time_step(scene, solid)
    sim = _pipeline(scene, solid, dt)
    _add_recorders(sim, scene, solid, Path(out) if out is not None else scene.output.directory)
    log.info(
        "effects: %s; %d steps to t = %.4g s",
        ", ".join(sim.effects),
        sim.num_steps,
        sim.num_steps * dt,
    )
    return sim


@dataclass
class _Solid:
    """The discretised body: its communicator and mesh, the P1/Q1 vector space, the owned
    nodes' reference coordinates (m) and lumped masses (kg), its displacement and velocity
    fields, its element technology with the linear elastic force of that technology (the
    tangent at rest of every material), and the stable steps (s) from the largest
    eigenvalue and from the shortest edge."""

    comm: MPI.Comm
    body: BodyMesh
    V: object
    X: np.ndarray
    mass: np.ndarray
    u: GhostedField
    v: GhostedField
    technology: Technology
    elastic: ElementForce
    dt_stable: float
    dt_element: float

    @property
    def owned(self) -> int:
        return len(self.X)


def _solid(scene: Scene, comm: MPI.Comm, body: BodyMesh | None) -> _Solid:
    """The body of the scene's ``[mesh]`` (or ``body``), with its mass, its element
    technology and stable step."""
    spec = scene.mesh
    if body is None and spec is None:
        raise SceneError(f"{scene.source}: mesh: missing (give [mesh], or a body to the API)")
    if body is not None:
        comm = body.msh.comm  # the caller's mesh: it lives as long as the caller keeps it
    else:  # keep the caller's comm: a DOLFINx 0.5 mesh's comm dies with the mesh
        try:
            body = body_mesh(comm, spec)
        except ValueError as err:  # a file gmsh cannot read, mixed cell types, ...
            where = "mesh.file" if spec.file is not None else "mesh"
            raise SceneError(f"{scene.source}: {where}: {err}") from None
    if spec is not None and spec.noise is not None:
        perturb(body, *spec.noise)
    cell = body.msh.topology.cell_type.name
    if cell not in ("tetrahedron", "hexahedron"):
        raise SceneError(
            f"{scene.source}: mesh: {cell} cells; allowed: tetrahedra or hexahedra (a volume)"
        )
    element = scene.element
    try:
        technology = Technology.choose(
            cell, element.integration, element.hourglass, element.hourglass_coefficient
        )
    except ValueError as err:  # e.g. reduced integration on a file of tetrahedra
        raise SceneError(f"{scene.source}: {err} (the mesh has {cell} cells)") from None
    V = _compat.vector_space(body.msh)
    X = V.tabulate_dof_coordinates()[: V.dofmap.index_map.size_local].copy()
    try:
        mass = lumped_mass(V, scene.material.density)
    except ValueError as err:
        raise SceneError(f"{scene.source}: mesh: {err}") from None
    u, v = GhostedField(V), GhostedField(V)
    elastic = ElementForce(V, replace(scene.material, model="linear_elastic"), technology, u, v)
    dt_stable = critical_time_step(elastic, mass, X, comm)
    dt_element = element_time_step(V, scene.material)
    return _Solid(comm, body, V, X, mass, u, v, technology, elastic, dt_stable, dt_element)


def _time_step(scene: Scene, solid: _Solid) -> float:
    """The scene's ``run.dt`` if it is stable, else ``run.dt_scale`` of the stable step (s)."""
    if scene.run.dt is not None:
        if scene.run.dt > solid.dt_stable:
            raise SceneError(
                f"{scene.source}: run.dt: {scene.run.dt:g} s is above the stable limit "
                f"{solid.dt_stable:.6g} s (2/omega_max); use a smaller dt or drop it to use "
                "dt_scale"
            )
        dt = scene.run.dt
    else:
        dt = _round_down(scene.run.dt_scale * solid.dt_stable)
    log.info(
        "mesh: %d %s cells, %d nodes; %s; stable dt %.4g s (eigenvalue), %.4g s (shortest edge /"
        " c_p); dt = %.4g s",
        solid.body.num_cells,
        solid.body.msh.topology.cell_type.name,
        solid.V.dofmap.index_map.size_global,
        solid.technology.describe(),
        solid.dt_stable,
        solid.dt_element,
        dt,
    )
    return dt


def _pipeline(scene: Scene, solid: _Solid, dt: float) -> Simulation:
    """The state at t = 0 and the effects the scene asks for, in the order they act."""
    state = State(X=solid.X, mass=solid.mass, dt=dt, u=solid.u.owned, v=solid.v.owned)
    state.v[:] = scene.initial.velocity
    comm = solid.comm
    internal = solid.elastic
    if scene.material.model != "linear_elastic":
        internal = ElementForce(solid.V, scene.material, solid.technology, solid.u, solid.v)
    return Simulation(
        state=state,
        end_time=scene.run.end_time,
        internal=internal,
        comm=comm,
        forces=[] if scene.gravity is None else [Gravity(scene.gravity, state)],
        walls=[_wall(scene, i, solid, state, comm) for i in range(len(scene.walls))],
        boundaries=[_boundary(scene, i, solid) for i in range(len(scene.boundaries))],
        info={
            "scene": scene.source,
            "dolfinx_version": _compat.DOLFINX_VERSION,
            "cell": solid.body.msh.topology.cell_type.name,
            "element": solid.technology.describe(),
            "cells": solid.body.num_cells,
            "nodes": solid.V.dofmap.index_map.size_global,
            "mass": comm.allreduce(float(solid.mass.sum())),
            "dt_stable": solid.dt_stable,
            "dt_element_estimate": solid.dt_element,
        },
    )


def _add_recorders(sim: Simulation, scene: Scene, solid: _Solid, directory: Path) -> None:
    """The history (always), the stable-step monitor of a hyperelastic body, and the
    fields and frames the scene asks for."""
    owned = np.arange(solid.owned, dtype=np.int32)
    guards = Guards(
        sim.comm,
        solid.V.dofmap.index_map.local_to_global(owned),
        max_energy_error=scene.run.max_energy_error,
        min_dt=scene.run.min_dt,
    )
    sim.history = History(
        sim,
        directory,
        every=scene.output.history_interval,
        guards=guards,
        plot=scene.output.plot,
    )
    if scene.material.model != "linear_elastic":
        from rwall_fem.hyperelasticity import StableStepMonitor

        monitor = StableStepMonitor(sim.internal, sim.state, solid.dt_stable, sim.comm)
        sim.recorders.append(monitor)
    if scene.output.fields:
        from rwall_fem.output.fields import Fields

        fields = Fields(
            directory,
            count=scene.output.fields,
            num_steps=sim.num_steps,
            V=solid.V,
            material=scene.material,
        )
        sim.recorders.append(fields)
    if scene.output.frames:
        from rwall_fem.output.frames import Frames

        frames = Frames(
            directory,
            count=scene.output.frames,
            num_steps=sim.num_steps,
            V=solid.V,
            walls=sim.walls,
            speed=float(np.linalg.norm(scene.initial.velocity)),
            color=scene.output.color,
        )
        sim.recorders.append(frames)


def _wall(scene: Scene, i: int, solid: _Solid, state: State, comm: MPI.Comm) -> RigidWall:
    """Wall ``i`` of the scene with its shape, motion, tangential law and secondary nodes."""
    spec: WallSpec = scene.walls[i]
    where = f"{scene.source}: wall[{i}]"
    point = np.asarray(spec.point)
    noise = scene.mesh.noise if scene.mesh is not None else None
    if spec.motion is not None and noise is not None:
        # The main node is a node of the model: noise moves it too, with an id no mesh
        # node has. The wall's orientation follows where it is defined from M.
        point = point + coordinate_noise([2**62 + i], *noise)[0]
    arguments = {key: getattr(spec, key) for key in SHAPE_KEYS[spec.kind]}
    try:
        shape = SHAPES[spec.kind](point, **arguments)
    except ValueError as err:
        raise SceneError(f"{where}: {err} (after coordinate noise)") from None

    motion = None
    if spec.motion is not None:
        if spec.motion.prescribed:
            motion = PrescribedMotion(spec.motion.velocity)
        else:
            motion = MainNodeMotion(spec.motion.mass, spec.motion.velocity)
    return RigidWall(
        shape,
        _secondary_nodes(spec, where, shape, solid, state),
        f"wall[{i}]",
        slide=spec.slide,
        friction=spec.friction,
        filter_alpha=_filter_alpha(spec, where, state.dt),
        motion=motion,
        comm=comm,
    )


def _filter_alpha(spec: WallSpec, where: str, dt: float) -> float:
    """The friction filter's alpha in (0, 1] from its coefficient, steps or frequency (Hz)
    at the step ``dt`` (s); 1 (no filter) when none is given."""
    if spec.friction_filter is None:
        return 1.0
    how, value = spec.friction_filter
    alpha = {"coefficient": value, "steps": 2 * np.pi / max(value, 1e-300)}.get(
        how, 2 * np.pi * value * dt
    )
    if not 0.0 < alpha <= 1.0:
        raise SceneError(
            f"{where}.friction_filter.{how}: gives alpha = {alpha:.4g} with dt = "
            f"{dt:.4g} s; alpha must be in (0, 1]"
        )
    return alpha


def _boundary(scene: Scene, i: int, solid: _Solid) -> VelocityBoundary:
    """Boundary condition ``i`` of the scene on the owned nodes of its named group."""
    spec = scene.boundaries[i]
    if spec.group not in solid.body.groups:
        known = ", ".join(sorted(solid.body.groups)) or "none"
        raise SceneError(
            f"{scene.source}: boundary[{i}].group: unknown node set {spec.group!r}; "
            f"the mesh has: {known}"
        )
    nodes = _owned(group_nodes(solid.V, solid.body, spec.group), solid.owned)
    return VelocityBoundary(f"boundary[{i}]", nodes, spec.velocity, spec.components)


def _secondary_nodes(spec: WallSpec, where: str, shape, solid: _Solid, state: State) -> np.ndarray:
    """Owned secondary nodes (``docs/theory.md``, "Secondary nodes"): boundary nodes by
    default; or nodes with 0 <= d <= search_distance at the start, plus named sets; minus
    excluded sets."""
    V, body, owned = solid.V, solid.body, solid.owned
    sec = spec.secondary
    for key, names in (("add", sec.add), ("exclude", sec.exclude)):
        for name in names:
            if name not in body.groups:
                known = ", ".join(sorted(body.groups)) or "none"
                raise SceneError(
                    f"{where}.secondary.{key}: unknown node set {name!r}; the mesh has: {known}"
                )
    selected = np.zeros(owned, dtype=bool)
    if sec.search_distance is None and not sec.add:
        selected[_owned(boundary_nodes(V), owned)] = True
    if sec.search_distance is not None:
        # The mesher leaves round-off (1e-19 m seen) on nodes placed at d = 0: distances
        # within 1e-10 of the body size count as zero, the tolerance of degenerate walls.
        comm = V.mesh.comm
        low, high = np.empty(3), np.empty(3)
        comm.Allreduce(state.X.min(axis=0, initial=np.inf), low, op=MPI.MIN)
        comm.Allreduce(state.X.max(axis=0, initial=-np.inf), high, op=MPI.MAX)
        d = shape.distance(state.X)
        selected |= (d >= -1e-10 * np.linalg.norm(high - low)) & (d <= sec.search_distance)
    for name in sec.add:
        selected[_owned(group_nodes(V, body, name), owned)] = True
    for name in sec.exclude:
        selected[_owned(group_nodes(V, body, name), owned)] = False
    return np.flatnonzero(selected)


def _owned(nodes: np.ndarray, owned: int) -> np.ndarray:
    return nodes[nodes < owned]


def _round_down(dt: float, digits: int = 4) -> float:
    """``dt`` rounded down to ``digits`` significant figures, identical on every partitioning."""
    unit = 10.0 ** (math.floor(math.log10(dt)) - digits + 1)
    return math.floor(dt / unit) * unit
