"""From a validated scene to a ready-to-run :class:`~rwall_fem.solver.Simulation`.

Data flows one way: scene -> checks that need no mesh (the results folder, the size
limits of :mod:`rwall_fem.estimate`) -> body (mesh, space, lumped mass, element
technology, stable step at rest) -> pipeline (internal force, the step size of
:mod:`rwall_fem.time_step`, body forces, walls, boundary conditions: only what the
scene asks for) -> what the starter of Radioss would warn about (nodes starting behind a
wall, walls without nodes, nodes both clamped and held by a wall) -> recorders (history,
run log, fields, frames) and the checkpoints.

Every check that can fail on one rank alone (gmsh runs on rank 0; the results folder is
checked there) is agreed on by all ranks, so a refusal is the same everywhere.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem import __version__, _compat
from rwall_fem.body import (
    Body,
    Part,
    PartError,
    part_masses,
    parts_of,
    piece_overlaps,
    shared_velocities,
    technologies,
)
from rwall_fem.boundary import VelocityBoundary
from rwall_fem.checkpoint import Checkpoints, body_digest, scene_keys
from rwall_fem.effects import Gravity
from rwall_fem.elements import GhostedField
from rwall_fem.estimate import (
    LIFT_HINT,
    estimate,
    refuse_above_limits,
    steps_above_limit,
    unphysical_material,
)
from rwall_fem.loads import (
    Factor,
    NodalForce,
    Pressure,
    RayleighDamping,
    added_masses,
    damped_step_factor,
    outer_faces,
)
from rwall_fem.mechanics import critical_time_step, shortest_edge
from rwall_fem.meshing import (
    BodyMesh,
    MeshTooLarge,
    body_mesh,
    boundary_nodes,
    coordinate_noise,
    group_nodes,
    perturb,
)
from rwall_fem.output.folder import ResultsFolder, check_folder
from rwall_fem.output.guards import Guards
from rwall_fem.output.history import History, history_schedule
from rwall_fem.output.run_log import RunLog, cycle_schedule
from rwall_fem.output.summary import truthful_when_interrupted
from rwall_fem.provenance import git_hash
from rwall_fem.rigid_body import RigidBodyError, build_rigid_bodies, deactivate_rigid_cells
from rwall_fem.rigid_contact import RigidContact
from rwall_fem.scene import SHAPE_KEYS, Scene, SceneError, WallSpec, load_scene
from rwall_fem.solver import CentralDifference, Simulation, State
from rwall_fem.time_step import step_size
from rwall_fem.units import parse_system
from rwall_fem.walls import RigidWall
from rwall_fem.walls.motion import MainNodeMotion, PrescribedMotion
from rwall_fem.walls.shapes import SHAPES

__all__ = ["build_simulation", "run_in_folder", "run_scene"]

log = logging.getLogger("rwall_fem")

# The mesher leaves round-off (1e-19 m seen) on nodes placed on a wall: distances within
# this fraction of the body's size count as zero, the tolerance of degenerate walls.
_ROUND_OFF = 1e-10


def run_scene(
    scene: Scene | str | Path,
    out: str | Path | None = None,
    overrides=(),
    comm: MPI.Comm = MPI.COMM_WORLD,
    *,
    limits: bool = True,
    resume: bool = False,
) -> dict:
    """Build and run a scene (object or TOML path) in its results folder, held for the run
    (:class:`~rwall_fem.output.folder.ResultsFolder`); returns the summary written to
    ``out``. ``limits=False`` lifts the size limits (``run.max_*``); with ``resume``, the
    run continues from the checkpoint in ``out`` (:mod:`rwall_fem.checkpoint`)."""
    if not isinstance(scene, Scene):
        scene = load_scene(scene, list(overrides))
    sim = build_simulation(scene, comm, out, limits=limits)
    run_in_folder(sim, resume=resume)
    return sim.history.summary


def run_in_folder(
    sim: Simulation, said: Callable[[Simulation], None] | None = None, *, resume: bool = False
) -> None:
    """Run ``sim`` while holding its results folder (a
    :class:`~rwall_fem.output.folder.ResultsFolder`: locked, and for a fresh run the
    outputs of an earlier run removed, as ``run.log`` says; with ``resume``, continued from
    its checkpoint instead); ``said(sim)`` reports how it ended before the last outputs
    are awaited, and ``run.log`` ends with the time the outputs took."""
    run_log = next(r for r in sim.recorders if isinstance(r, RunLog))
    with ResultsFolder(sim.history.directory, sim.comm, fresh=not resume) as folder:
        if resume:
            sim.checkpoints.resume(sim)
        if folder.removed:
            run_log.facts.append(
                f"removed the outputs of an earlier run: {', '.join(folder.removed)}"
            )
        with truthful_when_interrupted(sim):
            sim.run()
            if said is not None:
                said(sim)
            sim.history.wait()
        line = f"outputs written {time.perf_counter() - run_log.ended_at:.2f} s after the time loop"
        if run_log.frames:
            log.info("%s", line)
        run_log.write(line)


def build_simulation(
    scene: Scene,
    comm: MPI.Comm = MPI.COMM_WORLD,
    out: str | Path | None = None,
    *,
    body: BodyMesh | None = None,
    limits: bool = True,
) -> Simulation:
    """Mesh the body, lump its mass, choose dt and assemble the pipeline.

    ``body`` is a mesh of your own (``BodyMesh(msh, facet_tags, groups)``, any
    distributed DOLFINx mesh of tetrahedra or hexahedra); it replaces the
    scene's ``[mesh]`` and sets the communicator. Outputs go to ``out``, by default
    the scene's ``output.directory``; that folder is checked first (nothing is written
    to it here). Unless ``limits`` is False, a scene whose estimated or counted cells,
    steps or frames pass ``run.max_cells``, ``run.max_steps`` or ``run.max_frames`` is
    refused (before meshing when the estimate passes them).
    """
    directory = Path(out) if out is not None else scene.output.directory
    where = "--out" if out is not None else f"{scene.source}: output.directory"
    check_folder(directory, where, comm)
    if limits:
        refuse_above_limits(scene, estimate(scene, comm.size))
    solid = _solid(scene, comm, body, scene.run.max_cells if limits else None)
    sim = _pipeline(scene, solid, limits)
    if scene.contacts:
        from rwall_fem.contact import build_contacts

        sim.contacts = build_contacts(scene, solid, sim.state, sim.internal)
        sim.step_size.contacts = sim.contacts
        if sim.step_size.varies and not sim.internal.books_work:
            # Contact makes the step vary: the stored energies take its correction.
            sim.internal.books_work = True
            sim.update = CentralDifference(sim.state, sim.internal)
    dt = sim.state.dt
    if limits:
        steps_above_limit(scene, sim.planned_steps, dt)
    about = "" if sim.step_size.mode == "fixed" else "about "
    facts = [
        _mesh_fact(solid),
        *([_parts_fact(solid, solid.comm)] if scene.parts else []),
        _step_fact(sim),
        f"effects: {', '.join(sim.effects)}; {about}{sim.planned_steps} steps to t = "
        f"{scene.run.end_time:.4g} s",
    ]
    for line in facts:
        log.info("%s", line)
    touching = [set(c.main + c.secondary) or {p.name for p in solid.parts} for c in scene.contacts]
    overlaps = piece_overlaps(sim.internal, solid.X, sim.comm, touching)
    warnings = _starter_warnings(sim, solid) + overlaps
    for line in warnings:
        log.warning("%s", line)
    sim.info["warnings"] = warnings
    facts += [*_constraint_facts(sim), *(c.describe() for c in sim.contacts)]
    facts += [f"warning: {w}" for w in warnings]
    _add_recorders(sim, scene, solid, directory, facts)
    identity = {
        "code": __version__,
        "dolfinx": _compat.DOLFINX_VERSION,
        "scene": scene_keys(scene),
        "body": body_digest(sim.state),
    }
    sim.checkpoints = Checkpoints(
        directory / "checkpoint",
        sim.comm,
        identity,
        steps=scene.output.checkpoint_steps,
        seconds=scene.output.checkpoint_seconds,
    )
    return sim


@dataclass
class _Solid:
    """The discretised body: its communicator and mesh, the P1/Q1 vector space, the owned
    nodes' reference coordinates (m) and lumped masses (kg, and per part), its
    displacement and velocity fields, its parts with the linear elastic force of their
    technologies (the tangent at rest of every material), the stable step at rest (s)
    from the largest eigenvalue, and the diagonal of its box (m)."""

    comm: MPI.Comm
    body: BodyMesh
    V: object
    X: np.ndarray
    mass: np.ndarray
    part_masses: np.ndarray
    u: GhostedField
    v: GhostedField
    parts: list[Part]
    elastic: Body
    dt_stable: float
    size: float
    shells: bool = False  # a body of shells (rwall_fem.shells): elastic is its ShellBody

    @property
    def owned(self) -> int:
        return len(self.X)


def _solid(scene: Scene, comm: MPI.Comm, body: BodyMesh | None, max_cells) -> _Solid:
    """The body of the scene's ``[mesh]`` (or ``body``), with its parts, their mass and
    element technologies and the stable step; refused above ``max_cells`` cells (None: no
    limit)."""
    spec = scene.mesh
    if body is None and spec is None and not scene.pieces:
        raise SceneError(f"{scene.source}: mesh: missing (give [mesh] or [[piece]], or a body "
                         "to the API)")  # fmt: skip
    if body is not None:
        comm = body.msh.comm  # the caller's mesh: it lives as long as the caller keeps it
    else:  # keep the caller's comm: a DOLFINx 0.5 mesh's comm dies with the mesh
        try:
            if spec is None:
                from rwall_fem.pieces import pieces_mesh

                body = pieces_mesh(comm, scene.pieces, max_cells)
            else:
                body = body_mesh(comm, spec, max_cells)
        except MeshTooLarge as err:
            raise SceneError(
                f"{scene.source}: run.max_cells: the mesh has {err.cells} cells, more than "
                f"run.max_cells = {max_cells:g}; coarsen the mesh, raise run.max_cells, "
                f"{LIFT_HINT}"
            ) from None
        except ValueError as err:  # a file gmsh cannot read, mixed cell types, ...
            where = "mesh" if spec is None or spec.file is None else "mesh.file"
            where = "piece" if spec is None else where
            raise SceneError(f"{scene.source}: {where}: {err}") from None
    cell = body.msh.topology.cell_type.name
    if body.msh.topology.dim == 2:
        from rwall_fem.shells.build import shell_solid

        return shell_solid(scene, comm, body)
    if spec is not None and spec.file is not None:
        from rwall_fem.shells.build import solid_keys_on_shells

        solid_keys_on_shells(scene, cell)
    if cell not in ("tetrahedron", "hexahedron"):
        raise SceneError(
            f"{scene.source}: mesh: {cell} cells; allowed: tetrahedra or hexahedra (a volume)"
        )
    specs = scene.body_parts
    try:
        chosen = technologies(specs, cell, explicit=bool(scene.parts))
        parts = parts_of(specs, body, chosen, comm)
    except PartError as err:
        raise SceneError(f"{scene.source}: {err}") from None
    V = _compat.vector_space(body.msh)
    if spec is not None and spec.noise is not None:
        if spec.file is not None:  # a built-in shape's noise was checked with the scene
            _noise_is_small(scene, shortest_edge(V))
        perturb(body, *spec.noise)
    X = V.tabulate_dof_coordinates()[: V.dofmap.index_map.size_local].copy()
    masses = part_masses(V, parts)
    if scene.added_masses:  # shared by the parts as their masses share the node
        added = added_masses(scene.added_masses, lambda i, name: _named_nodes(
            scene, f"added_mass[{i}]", name, V, body, len(X)), len(X), comm)  # fmt: skip
        total = masses.sum(axis=1)
        masses = masses + added[:, None] * masses / np.where(total > 0, total, 1.0)[:, None]
    mass = masses.sum(axis=1)
    lowest = comm.allreduce(float(mass.min(initial=np.inf)), op=MPI.MIN)
    if not lowest > 0.0:
        raise SceneError(
            f"{scene.source}: mesh: lumped mass is not positive (min {lowest:g} kg): the "
            f"element {cell} P1 is the only supported choice"
        )
    u, v = GhostedField(V), GhostedField(V)
    elastic = Body(V, [replace(p, material=replace(p.material, model="linear_elastic"))
                       for p in parts], u, v, explicit=bool(scene.parts))  # fmt: skip
    dt_stable = _stable_step(scene, elastic, mass, X, comm)
    low, high = np.empty(3), np.empty(3)
    comm.Allreduce(X.min(axis=0, initial=np.inf), low, op=MPI.MIN)
    comm.Allreduce(X.max(axis=0, initial=-np.inf), high, op=MPI.MAX)
    size = float(np.linalg.norm(high - low))
    return _Solid(comm, body, V, X, mass, masses, u, v, parts, elastic, dt_stable, size)


def _noise_is_small(scene: Scene, edge: float) -> None:
    """The rule of the scene's built-in shapes for a mesh file: a noise amplitude of at
    most 0.1 x the shortest edge (m)."""
    amplitude = scene.mesh.noise[0]
    if amplitude > 0.1 * edge:
        raise SceneError(
            f"{scene.source}: mesh.noise.amplitude: {amplitude:g} m is more than 0.1 x the "
            f"shortest edge of the mesh file ({edge:g} m): it would distort the elements and "
            f"shrink the stable step; at most {0.1 * edge:g} m"
        )


def _stable_step(scene: Scene, elastic: Body, mass, X, comm) -> float:
    """The stable step (s) of :func:`critical_time_step`, or one line naming the material
    when the eigenvalue cannot be found (e.g. a density off by orders of magnitude)."""
    from petsc4py import PETSc

    try:
        dt = critical_time_step(elastic, mass, X, comm)
    except (RuntimeError, PETSc.Error) as err:
        reason = " ".join(str(err).split())
        dt = math.nan
    else:
        reason = f"it came out as {dt:g} s"
    if not (math.isfinite(dt) and dt > 0.0):
        raise unphysical_material(scene, reason)
    return dt


def _mesh_fact(solid: _Solid) -> str:
    return (
        f"mesh: {solid.body.num_cells} {solid.body.msh.topology.cell_type.name} cells, "
        f"{solid.V.dofmap.index_map.size_global} nodes; {_technology(solid.parts)}"
    )


def _technology(parts: list[Part]) -> str:
    """The element technology, part by part when the parts differ."""
    kinds = {part.technology.describe() for part in parts}
    if len(kinds) == 1:
        return kinds.pop()
    return "; ".join(f"{part.name}: {part.technology.describe()}" for part in parts)


def _parts_fact(solid: _Solid, comm) -> str:
    """A line per part: its material, cells and mass."""
    lines = []
    for k, part in enumerate(solid.parts):
        cells = comm.allreduce(len(part.cells))
        mass = comm.allreduce(float(solid.part_masses[:, k].sum()))
        lines.append(f"{part.name} ({part.material.model}, {cells} cells, {mass:.6g} kg)")
    return "parts: " + "; ".join(lines)


def _step_fact(sim: Simulation) -> str:
    """The step, and both stable steps at rest: the eigenvalue's and the elements'."""
    info, step = sim.info, sim.step_size
    how = (
        "adaptive: dt_scale x the smallest estimate of the cells, calibration "
        f"{step.calibration:.4g}"
        if step.mode == "adaptive"
        else "fixed"
    )
    source = "L_c / c" if info["cell"] in ("quadrilateral", "triangle") else "eigenvalue"
    return (
        f"time step {how}; at rest: stable {info['dt_stable']:.4g} s ({source}), smallest "
        f"L/c of a cell {info['dt_element_estimate']:.4g} s; dt = {sim.state.dt:.4g} s"
    )


def _pipeline(scene: Scene, solid: _Solid, limits: bool) -> Simulation:
    """The state at t = 0, the step size and the effects the scene asks for, in the order
    they act."""
    comm = solid.comm
    internal = solid.elastic
    nonlinear = any(part.material.model != "linear_elastic" for part in solid.parts)
    if nonlinear and not solid.shells:
        internal = Body(solid.V, solid.parts, solid.u, solid.v, explicit=bool(scene.parts))
    internal.part_masses = solid.part_masses.copy()
    if reason := shared_velocities(internal, comm):
        raise SceneError(f"{scene.source}: part: {reason}")
    body_mass = comm.allreduce(float(solid.mass.sum()))
    damping = scene.damping
    stable = solid.dt_stable  # with damping, the damped limit (rwall_fem.loads)
    if damping is not None:
        factor = damped_step_factor(damping.alpha, damping.beta, solid.dt_stable)
        if factor < 1e-6:
            raise SceneError(
                f"{scene.source}: damping: alpha = {damping.alpha:g} 1/s, beta = "
                f"{damping.beta:g} s damp the mesh's highest mode so much that the stable step "
                f"would be {factor:.3g} of the undamped {solid.dt_stable:.4g} s; lower them"
            )
        stable *= factor
    steps = step_size(scene, internal, stable, V=solid.V, body_mass=body_mass,
                      limits=limits)  # fmt: skip
    state = State(X=solid.X, mass=solid.mass, dt=steps.initial, u=solid.u.owned, v=solid.v.owned)
    held = internal.held[: solid.owned] > 0
    for k, part in enumerate(solid.parts):
        state.v[held[:, k]] = part.velocity
    walls = [_wall(scene, i, solid, state, comm) for i in range(len(scene.walls))]
    boundaries = [_boundary(scene, i, solid) for i in range(len(scene.boundaries))]
    rigid = _rigid_bodies(scene, solid, state, walls, boundaries)
    if rigid and solid.shells:
        from rwall_fem.shells.rigid import carry_rotations

        carry_rotations(rigid, internal, comm)
    inactive = deactivate_rigid_cells(internal, rigid, solid.V, comm) if rigid else 0
    update = None
    if solid.shells:
        from rwall_fem.shells.update import ShellUpdate

        update = ShellUpdate(state, internal)
    return Simulation(
        update=update,
        state=state,
        end_time=scene.run.end_time,
        internal=internal,
        comm=comm,
        step_size=steps,
        forces=([] if scene.gravity is None else [Gravity(scene.gravity)])
        + _loads(scene, solid),
        walls=walls,
        boundaries=boundaries,
        rigid_bodies=rigid,
        rigid_contact=RigidContact(rigid, walls, solid.owned, comm) if rigid else None,
        info={
            "scene": scene.source,
            "version": __version__,
            "git_hash": comm.bcast(git_hash() if comm.rank == 0 else None, root=0),
            "dolfinx_version": _compat.DOLFINX_VERSION,
            "cell": solid.body.msh.topology.cell_type.name,
            "element": _technology(solid.parts),
            "cells": solid.body.num_cells,
            "nodes": solid.V.dofmap.index_map.size_global,
            "mass": body_mass,
            "dt_stable": solid.dt_stable,
            "dt_element_estimate": steps.at_rest,
            **({"rigid_cells": inactive} if rigid else {}),
        },
    )


def _rigid_bodies(scene: Scene, solid: _Solid, state: State, walls, boundaries) -> list:
    """The scene's [[rigid_body]]s on their owned nodes (named sets, every node of the named
    parts, the nodes inside a box at the start), and what they may not meet: a boundary
    condition on their nodes, mass scaling."""
    specs, comm, owned = scene.rigid_bodies, solid.comm, solid.owned
    if not specs:
        return []
    names = [part.name for part in solid.parts]
    selections = []
    for i, spec in enumerate(specs):
        where = f"{scene.source}: rigid_body[{i}]"
        chosen = np.zeros(owned, dtype=bool)
        for name in spec.sets:
            if name not in solid.body.groups:
                known = ", ".join(sorted(solid.body.groups)) or "none"
                raise SceneError(f"{where}.sets: unknown node set {name!r}; the mesh has: {known}")
            chosen[_owned(group_nodes(solid.V, solid.body, name), owned)] = True
        for name in spec.parts:
            if name not in names:
                raise SceneError(f"{where}.parts: unknown part {name!r}; the parts: "
                                 f"{', '.join(names)}")  # fmt: skip
            chosen |= solid.elastic.held[:owned, names.index(name)] > 0
        if spec.box is not None:
            slack = _ROUND_OFF * solid.size
            low, high = np.array(spec.box.low) - slack, np.array(spec.box.high) + slack
            chosen |= np.all((state.X >= low) & (state.X <= high), axis=1)
        selections.append(np.flatnonzero(chosen))
    try:
        bodies = build_rigid_bodies(specs, selections, state, comm, scene.gravity, solid.size)
    except RigidBodyError as err:
        raise SceneError(f"{scene.source}: {err}") from None
    if scene.run.dt_min_action == "mass_scaling":
        raise SceneError(f"{scene.source}: run.dt_min_action: 'mass_scaling' with "
                         "[[rigid_body]] is not supported (a rigid body's mass is fixed); use "
                         "'stop' or 'erode'")  # fmt: skip
    for body in bodies:
        for b in boundaries:
            shared = comm.allreduce(len(np.intersect1d(b.nodes, body.nodes)))
            if shared:
                raise SceneError(f"{scene.source}: {b.name}: prescribes {shared} nodes of "
                                 f"{body.name}: a boundary condition on a rigid body's nodes "
                                 "is not supported")  # fmt: skip
    return bodies


def _add_recorders(
    sim: Simulation, scene: Scene, solid: _Solid, directory: Path, facts: list[str]
) -> None:
    """The history and the run log (always; ``facts`` are the run log's lines on what was
    built), the stable-step monitor of a hyperelastic body, and the fields and frames the
    scene asks for. The run log is the first recorder: it closes right after the history,
    before the fields and frames, and says what is still being written."""
    owned = np.arange(solid.owned, dtype=np.int32)
    guards = Guards(
        sim.comm,
        solid.V.dofmap.index_map.local_to_global(owned),
        max_energy_error=scene.run.max_energy_error,
    )
    sim.history = History(
        sim,
        directory,
        schedule=history_schedule(scene.output),
        guards=guards,
        plot=scene.output.plot,
        units=parse_system(scene.output.units),
    )
    run_log = RunLog(
        directory, scene, facts, comm=sim.comm, frames=scene.output.frames,
        schedule=cycle_schedule(scene.run.end_time, scene.output.print_interval),
    )  # fmt: skip
    sim.recorders.append(run_log)
    loads = None
    if sim.contacts:
        from rwall_fem.output.contact_loads import ContactLoads

        to_global = solid.V.dofmap.index_map.local_to_global
        loads = ContactLoads(sim.contacts, sim.comm, to_global(owned))
    if scene.output.fields:
        from rwall_fem.output.fields import Fields

        fields = Fields(
            directory,
            count=scene.output.fields,
            end_time=scene.run.end_time,
            V=solid.V,
            parts=solid.parts,
            contact=loads,
        )
        sim.recorders.append(fields)
    if scene.output.frames:
        from rwall_fem.output.coloring import COLORS
        from rwall_fem.output.frames import Frames
        from rwall_fem.scene.view import check_view

        color, fields = scene.output.color, sorted(sim.internal.cell_fields(sim.state))
        if color == "contact_pressure" and loads is None:
            raise SceneError(f"{scene.source}: output.color: 'contact_pressure' needs contact: "
                             "add a [[contact]] table, or choose another colour")  # fmt: skip
        if color not in COLORS and color not in fields:
            models = ", ".join(sorted({part.material.model for part in solid.parts}))
            raise SceneError(
                f"{scene.source}: output.color: {color!r} is not a field of this body "
                f"({', '.join(fields) or 'no cell fields'} for {models}); "
                f"use one of {', '.join(COLORS)}"
            )
        view = scene.output.view
        if view is not None:
            names = [part.name for part in solid.parts] if scene.parts else []
            check_view(view, solid.X, names, scene.source, solid.comm)
        frames = Frames(
            directory,
            count=scene.output.frames,
            end_time=scene.run.end_time,
            V=solid.V,
            walls=sim.walls,
            speed=max(float(np.linalg.norm(part.velocity)) for part in solid.parts),
            gravity=scene.gravity,
            color=color,
            parts=[part.name for part in solid.parts] if scene.parts else (),
            view=view,
            contact=loads if color == "contact_pressure" else None,
        )
        sim.recorders.append(frames)


def _wall(scene: Scene, i: int, solid: _Solid, state: State, comm: MPI.Comm) -> RigidWall:
    """Wall ``i`` of the scene with its shape, motion, tangential law and secondary nodes."""
    spec: WallSpec = scene.walls[i]
    where = f"{scene.source}: wall[{i}]"
    point = np.asarray(spec.point)
    noise = scene.mesh.noise if scene.mesh is not None else None
    moved = spec.motion is not None and noise is not None
    if moved:
        # The main node is a node of the model: noise moves it too, with an id no mesh
        # node has. The wall's orientation follows where it is defined from M.
        point = point + coordinate_noise([2**62 + i], *noise)[0]
    arguments = {key: getattr(spec, key) for key in SHAPE_KEYS[spec.kind]}
    try:
        shape = SHAPES[spec.kind](point, **arguments)
    except ValueError as err:
        raise SceneError(f"{where}: {err}{' (after coordinate noise)' if moved else ''}") from None

    motion = None
    if spec.motion is not None:
        if spec.motion.prescribed:
            motion = PrescribedMotion(spec.motion.velocity)
        else:
            motion = MainNodeMotion(spec.motion.mass, spec.motion.velocity, spec.motion.held or "")
    _filter_fits(spec, where, state.dt)
    return RigidWall(
        shape,
        _secondary_nodes(spec, where, shape, solid, state, _erodes(scene)),
        f"wall[{i}]",
        slide=spec.slide,
        friction=spec.friction,
        friction_filter=spec.friction_filter,
        dt=state.dt,
        motion=motion,
        comm=comm,
    )


def _erodes(scene: Scene) -> bool:
    """Whether cells of the body may erode: a failure criterion, or erosion below dt_min."""
    failing = any(getattr(p.material, "failure", None) for p in scene.body_parts)
    return failing or scene.run.dt_min_action == "erode"


def _filter_fits(spec: WallSpec, where: str, dt: float) -> None:
    """A friction filter's alpha is in (0, 1] at the step of the start ``dt`` (s) (a
    cut-off frequency gives 2 pi f dt: later steps are taken at most 1)."""
    if spec.friction_filter is None:
        return
    how, value = spec.friction_filter
    alpha = {"coefficient": value, "steps": 2 * np.pi / max(value, 1e-300)}.get(
        how, 2 * np.pi * value * dt
    )
    if not 0.0 < alpha <= 1.0:
        raise SceneError(
            f"{where}.friction_filter.{how}: gives alpha = {alpha:.4g} with dt = "
            f"{dt:.4g} s; alpha must be in (0, 1]"
        )


def _named_nodes(scene: Scene, where: str, names, V, body: BodyMesh, owned: int):
    """The owned nodes of the union of the node sets ``names`` that ``where`` (a table of
    the scene) names, each node once, or one line refusing an unknown set."""
    for name in names:
        if name not in body.groups:
            known = ", ".join(sorted(body.groups)) or "none"
            raise SceneError(
                f"{scene.source}: {where}.group: unknown node set {name!r}; the mesh has: {known}"
            )
    nodes = [group_nodes(V, body, name) for name in names]
    return _owned(np.unique(np.concatenate(nodes)).astype(np.int32), owned)


def _loads(scene: Scene, solid: _Solid) -> list:
    """The ``[[load]]`` forces and pressures, then the ``[damping]``, in that order."""
    if solid.shells:
        from rwall_fem.shells.loads import shell_loads

        return shell_loads(scene, solid)
    V, body, owned, comm = solid.V, solid.body, solid.owned, solid.comm
    forces = []
    for i, spec in enumerate(scene.loads):
        where, factor = f"load[{i}]", Factor(spec.history)
        nodes = _named_nodes(scene, where, spec.group, V, body, owned)
        if spec.kind == "force":
            force = np.asarray(spec.force)
            if spec.per == "set":
                force = force / max(comm.allreduce(len(nodes)), 1)
            forces.append(NodalForce(where, nodes, force, factor))
            continue
        tags = [body.facet_tags.find(body.groups[name]) for name in spec.group]
        faces = outer_faces(V, np.unique(np.concatenate(tags)))
        if not comm.allreduce(len(faces)):
            named = ", ".join(spec.group)
            raise SceneError(
                f"{scene.source}: {where}.group: {named}: no face on the outside of the "
                "body: a pressure acts on outer faces"
            )
        forces.append(Pressure(where, V, faces, spec.pressure, factor, solid.u))
    damping = scene.damping
    if damping is not None:
        nodes = np.arange(owned, dtype=np.int32)
        if damping.group is not None:
            nodes = _named_nodes(scene, "damping", damping.group, V, body, owned)
        forces.append(RayleighDamping(nodes, damping.alpha, damping.beta, solid.elastic))
    return forces


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
    if spec.rotations is not None:
        if not solid.shells:
            raise SceneError(
                f"{scene.source}: boundary[{i}].rotations: is for shells (nodes with "
                f"rotations); the mesh has {solid.body.msh.topology.cell_type.name} cells"
            )
        solid.elastic.hold_rotations(nodes, spec.rotations)
    return VelocityBoundary(f"boundary[{i}]", nodes, spec.velocity, spec.components)


def _secondary_nodes(
    spec: WallSpec, where: str, shape, solid: _Solid, state: State, erodes: bool
) -> np.ndarray:
    """Owned secondary nodes (``docs/theory.md``, "Secondary nodes"): boundary nodes by
    default (every node of a body whose cells may erode); or nodes with 0 <= d <=
    search_distance at the start, plus named sets, plus every node of the named parts;
    minus excluded sets."""
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
    if sec.search_distance is None and not sec.add and not sec.parts:
        if erodes or solid.shells:  # erosion bares the inside; a shell's nodes are all on it
            selected[:] = True
        else:
            selected[_owned(boundary_nodes(V), owned)] = True
    names = [part.name for part in solid.parts]
    for name in sec.parts:  # the scene checked the names
        selected |= solid.elastic.held[:owned, names.index(name)] > 0
    if sec.search_distance is not None:
        d = shape.distance(state.X)
        selected |= (d >= -_ROUND_OFF * solid.size) & (d <= sec.search_distance)
    for name in sec.add:
        selected[_owned(group_nodes(V, body, name), owned)] = True
    before = V.mesh.comm.allreduce(int(selected.sum()))
    for name in sec.exclude:
        selected[_owned(group_nodes(V, body, name), owned)] = False
    if before and not V.mesh.comm.allreduce(int(selected.sum())):
        raise SceneError(
            f"{where}.secondary.exclude: leaves the wall no secondary node (it removes all "
            f"{before} selected); exclude fewer node sets"
        )
    return np.flatnonzero(selected)


def _constraint_facts(sim: Simulation) -> list[str]:
    """A line per wall, boundary condition and rigid body: what it is and how many nodes
    it holds."""
    comm = sim.comm
    lines = []
    for w in sim.walls:
        count = comm.allreduce(len(w.nodes))
        lines.append(f"{w.name}: {w.shape.kind}, slide {w.slide}, {count} secondary nodes")
    for b in sim.boundaries:
        count = comm.allreduce(len(b.nodes))
        axes = "".join("xyz"[i] for i in b.axes)
        lines.append(f"{b.name}: {count} nodes, components {axes}")
    for r in sim.rigid_bodies:
        count = comm.allreduce(len(r.nodes))
        center = ", ".join(f"{c:.4g}" for c in r.center0)
        lines.append(f"{r.name}: {count} nodes, {r.mass:.6g} kg, centre of mass ({center}) m")
    if sim.rigid_bodies:
        lines.append(f"rigid bodies: {sim.info['rigid_cells']} cells inside them not computed")
    return lines


def _starter_warnings(sim: Simulation, solid: _Solid) -> list[str]:
    """What Radioss's starter warns about, one line each: secondary nodes that start
    behind a wall (kept there, ``docs/theory.md``), a wall without secondary nodes, nodes
    both prescribed by a boundary condition and secondary to a wall (the condition wins
    on its components: it acts after the walls)."""
    comm, warnings = sim.comm, []
    for w in sim.walls:
        w.find_initial_penetration(sim.state, _ROUND_OFF * solid.size)
        if w.initially_penetrated:
            x = ", ".join(f"{c:.4g}" for c in w.deepest_position)
            warnings.append(
                f"{w.name}: {w.initially_penetrated} secondary nodes start behind the wall, "
                f"the deepest {w.deepest_penetration:.4g} m at ({x}) m; the wall keeps them "
                "there unless one step takes them out (is the normal on the body's side? is "
                "the body where it should be?)"
            )
        if not comm.allreduce(len(w.nodes)):
            warnings.append(
                f"{w.name}: no secondary node; the wall acts on nothing (widen "
                "secondary.search_distance, or add node sets)"
            )
    for b in sim.boundaries:
        axes = "".join("xyz"[i] for i in b.axes)
        for w in sim.walls:
            shared = comm.allreduce(len(np.intersect1d(b.nodes, w.nodes)))
            if shared:
                warnings.append(
                    f"{b.name} prescribes components {axes} of {shared} nodes that are also "
                    f"secondary to {w.name}: on those components the boundary condition wins "
                    "(it acts after the walls), on the others the wall acts"
                )
    return warnings


def _owned(nodes: np.ndarray, owned: int) -> np.ndarray:
    return nodes[nodes < owned]
