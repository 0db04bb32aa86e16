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
from rwall_fem.history import History
from rwall_fem.mechanics import (
    critical_time_step,
    element_time_step,
    lumped_mass,
    stiffness_matrix,
)
from rwall_fem.meshing import bar_mesh, boundary_nodes, read_mesh
from rwall_fem.scene import Scene, SceneError, load_scene
from rwall_fem.solver import LinearElasticForce, Simulation, State
from rwall_fem.walls import PlaneWall, RigidWall

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
    scene: Scene, comm: MPI.Comm = MPI.COMM_WORLD, out: str | Path | None = None
) -> Simulation:
    """Mesh the body, assemble mass and stiffness, choose dt and assemble the pipeline."""
    directory = Path(out) if out is not None else scene.output.directory
    spec = scene.mesh
    if spec.file is not None:
        body = read_mesh(comm, spec.file)
    else:
        body = bar_mesh(comm, spec.origin, spec.size, spec.element_size, spec.cell, spec.axis)
    msh = body.msh
    V = _compat.vector_space(msh)
    owned = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:owned].copy()
    mass = lumped_mass(V, scene.material.density)
    K = stiffness_matrix(V, scene.material)

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
    walls = _walls(scene, V, owned)
    sim = Simulation(
        state=state,
        end_time=scene.run.end_time,
        internal=LinearElasticForce(K, state),
        constraints=walls,
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
        directory, scene.output.history_interval, sim.num_steps, comm, info, walls, state
    )
    sim.recorders.append(sim.history)
    if scene.output.frames:
        from rwall_fem.frames import Frames

        speed = float(np.linalg.norm(scene.initial.velocity))
        sim.recorders.append(Frames(directory, scene.output.frames, sim.num_steps, V, walls, speed))
    log.info(
        "effects: %s; %d steps to t = %.4g s",
        ", ".join(sim.effects),
        sim.num_steps,
        sim.num_steps * dt,
    )
    return sim


def _walls(scene: Scene, V, owned: int) -> list[RigidWall]:
    if not scene.walls:
        return []
    nodes = boundary_nodes(V)
    nodes = nodes[nodes < owned]
    return [
        RigidWall(PlaneWall(w.point, w.normal_point), nodes, f"wall[{i}]")
        for i, w in enumerate(scene.walls)
    ]


def _round_down(dt: float, digits: int = 4) -> float:
    """``dt`` rounded down to ``digits`` significant figures, identical on every partitioning."""
    unit = 10.0 ** (math.floor(math.log10(dt)) - digits + 1)
    return math.floor(dt / unit) * unit
