"""From a validated scene to a ready-to-run :class:`~rwall_fem.solver.Simulation`.

Data flows one way: scene -> body (mesh, space, mass, stiffness) -> stable
step -> effects pipeline (only what the scene asks for) -> recorders.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.boundary import VelocityBoundary
from rwall_fem.effects import Gravity
from rwall_fem.history import History
from rwall_fem.mechanics import (
    critical_time_step,
    element_time_step,
    lumped_mass,
    stiffness_matrix,
)
from rwall_fem.meshing import (
    BodyMesh,
    body_mesh,
    boundary_nodes,
    coordinate_noise,
    group_nodes,
    perturb,
)
from rwall_fem.scene import SHAPE_KEYS, Scene, SceneError, WallSpec, load_scene
from rwall_fem.solver import LinearElasticForce, Simulation, State
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
    """Mesh the body, assemble mass and stiffness, choose dt and assemble the pipeline.

    ``body`` is a mesh of your own (``BodyMesh(msh, facet_tags, groups)``, any
    distributed DOLFINx mesh of tetrahedra or hexahedra); it replaces the
    scene's ``[mesh]`` and sets the communicator.
    """
    directory = Path(out) if out is not None else scene.output.directory
    spec = scene.mesh
    if body is not None:
        comm = body.msh.comm
    elif spec is None:
        raise SceneError(f"{scene.source}: mesh: missing (give [mesh], or a body to the API)")
    else:
        try:
            body = body_mesh(comm, spec)
        except ValueError as err:  # e.g. a file with mixed cell types
            raise SceneError(f"{scene.source}: mesh: {err}") from None
    if spec is not None and spec.noise is not None:
        perturb(body, *spec.noise)
    msh = body.msh
    cell = msh.topology.cell_type.name
    if cell not in ("tetrahedron", "hexahedron"):
        raise SceneError(
            f"{scene.source}: mesh: {cell} cells; allowed: tetrahedra or hexahedra (a volume)"
        )
    V = _compat.vector_space(msh)
    owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:owned].copy()
    try:
        mass = lumped_mass(V, scene.material.density)
    except ValueError as err:
        raise SceneError(f"{scene.source}: mesh: {err}") from None
    K = stiffness_matrix(V, scene.material)  # small strain: also the tangent at u = 0

    dt_stable = critical_time_step(K, mass, X)
    dt_element = element_time_step(V, scene.material)
    if scene.run.dt is not None:
        if scene.run.dt > dt_stable:
            raise SceneError(
                f"{scene.source}: run.dt: {scene.run.dt:g} s is above the stable limit "
                f"{dt_stable:.6g} s (2/omega_max); use a smaller dt or drop it to use dt_scale"
            )
        dt = scene.run.dt
    else:
        dt = _round_down(scene.run.dt_scale * dt_stable)
    log.info(
        "mesh: %d %s cells, %d nodes; stable dt %.4g s (eigenvalue), %.4g s (shortest edge / c_p);"
        " dt = %.4g s",
        body.num_cells,
        msh.topology.cell_type.name,
        V.dofmap.index_map.size_global,
        dt_stable,
        dt_element,
        dt,
    )

    state = State(X=X, mass=mass, dt=dt)
    state.v[:] = scene.initial.velocity
    forces = [] if scene.gravity is None else [Gravity(scene.gravity, state)]
    walls = [_wall(scene, i, V, body, state, comm) for i in range(len(scene.walls))]
    boundaries = [_boundary(scene, i, V, body, owned) for i in range(len(scene.boundaries))]
    monitors = []
    if scene.material.model == "linear_elastic":
        internal = LinearElasticForce(K, state)
    else:
        from rwall_fem.hyperelasticity import HyperelasticForce, StableStepMonitor

        K.destroy()  # only the initial stable step needed it
        internal = HyperelasticForce(V, scene.material, state)
        monitors.append(StableStepMonitor(internal, state, dt_stable))
    sim = Simulation(
        state=state,
        end_time=scene.run.end_time,
        internal=internal,
        forces=forces,
        constraints=[*walls, *boundaries],  # clamps last: they win over walls
    )
    info = {
        "scene": scene.source,
        "dolfinx_version": _compat.DOLFINX_VERSION,
        "cell": msh.topology.cell_type.name,
        "cells": body.num_cells,
        "nodes": V.dofmap.index_map.size_global,
        "mass": comm.allreduce(float(mass.sum())),
        "dt_stable": dt_stable,
        "dt_element_estimate": dt_element,
    }
    sim.history = History(
        directory,
        scene.output.history_interval,
        sim.num_steps,
        comm,
        info,
        walls,
        state,
        node_ids=V.dofmap.index_map.local_to_global(np.arange(owned, dtype=np.int32)),
        max_energy_error=scene.run.max_energy_error,
        min_dt=scene.run.min_dt,
        plot=scene.output.plot,
        boundaries=boundaries,
    )
    sim.recorders += [sim.history, *monitors]
    if scene.output.fields:
        from rwall_fem.fields import Fields

        sim.recorders.append(
            Fields(directory, scene.output.fields, sim.num_steps, V, scene.material)
        )
    if scene.output.frames:
        from rwall_fem.frames import Frames

        speed = float(np.linalg.norm(scene.initial.velocity))
        frames = Frames(
            directory, scene.output.frames, sim.num_steps, V, walls, speed, scene.output.color
        )
        sim.recorders.append(frames)
    log.info(
        "effects: %s; %d steps to t = %.4g s",
        ", ".join(sim.effects),
        sim.num_steps,
        sim.num_steps * dt,
    )
    return sim


def _wall(scene: Scene, i: int, V, body, state: State, comm: MPI.Comm) -> RigidWall:
    """Wall ``i`` of the scene with its shape, motion, tangential law and secondary nodes."""
    spec: WallSpec = scene.walls[i]
    where = f"{scene.source}: wall[{i}]"
    point = np.asarray(spec.point)
    noise = scene.mesh.noise if scene.mesh is not None else None
    if spec.motion is not None and noise is not None:
        # The main node is a node of the model: noise moves it too (spec 6.5), with an
        # id no mesh node has. The wall's orientation follows where it is defined from M.
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

    alpha = 1.0
    if spec.friction_filter is not None:
        how, value = spec.friction_filter
        alpha = {"coefficient": value, "steps": 2 * np.pi / max(value, 1e-300)}.get(
            how, 2 * np.pi * value * state.dt
        )
        if not 0.0 < alpha <= 1.0:
            raise SceneError(
                f"{where}.friction_filter.{how}: gives alpha = {alpha:.4g} with dt = "
                f"{state.dt:.4g} s; alpha must be in (0, 1]"
            )
    nodes = _secondary_nodes(spec, where, shape, V, body, state)
    return RigidWall(
        shape,
        nodes,
        f"wall[{i}]",
        slide=spec.slide,
        friction=spec.friction,
        filter_alpha=alpha,
        motion=motion,
        comm=comm,
    )


def _boundary(scene: Scene, i: int, V, body, owned: int) -> VelocityBoundary:
    """Boundary condition ``i`` of the scene on the owned nodes of its named group."""
    spec = scene.boundaries[i]
    if spec.group not in body.groups:
        known = ", ".join(sorted(body.groups)) or "none"
        raise SceneError(
            f"{scene.source}: boundary[{i}].group: unknown node set {spec.group!r}; "
            f"the mesh has: {known}"
        )
    nodes = _owned(group_nodes(V, body, spec.group), owned)
    return VelocityBoundary(f"boundary[{i}]", nodes, spec.velocity, spec.components)


def _secondary_nodes(spec: WallSpec, where: str, shape, V, body, state: State) -> np.ndarray:
    """Owned secondary nodes (spec section 5): boundary nodes by default; or nodes with
    0 <= d <= search_distance at the start, plus named sets; minus excluded sets."""
    owned = len(state.X)
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
        # within 1e-10 of the body size count as zero, as the spec does for degeneracy.
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
