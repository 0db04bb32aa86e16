"""Frame data of a run, gathered on rank 0 and rendered by :mod:`rwall_fem.output.render`.

Each rank sends its cells, points, nodal values and the cell fields of the
internal force to rank 0 (connectivity offset by the points already received);
rank 0 stores them in ``frames/data``: ``mesh.npz`` once, then
``frame_NNNN.npz`` per frame (``t``, ``u``, ``v``, the walls' ``offsets`` and
``cell_<name>`` for each cell field; when cells can erode, ``cell_eroded`` and
``detached``, 1 at the nodes no live cell holds; when the frames are coloured by it,
``contact_pressure``, Pa, at the nodes: :mod:`rwall_fem.output.contact_loads`).
Each file is written whole (:mod:`rwall_fem.output.atomic`). Pictures are drawn by a
separate process, ``python -m rwall_fem.output.render DIR``, which never loads DOLFINx:
VTK's wheels crash when they render in a process that holds DOLFINx's C++ libraries (a
libstdc++ ABI clash, seen with vtk 9.7 and DOLFINx 0.5). With a free core that process
starts at the first frame and is fed each frame as it is written
(:mod:`rwall_fem.output.worker`); otherwise it starts at the end of the run (or of a
stopped or failed run). Either way every frame written is drawn.
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
from dolfinx import fem

from rwall_fem import _compat
from rwall_fem.output import OutputError
from rwall_fem.output.atomic import whole
from rwall_fem.output.schedule import Times
from rwall_fem.output.worker import RenderWorker, renderer_command, renderer_env, wanted
from rwall_fem.scene.view import view_to_json

__all__ = ["Frames"]


class Frames:
    """Recorder that stores ``count`` frames of the body (space ``V``) and its ``walls``,
    at times spread evenly over [0, ``end_time``] (s), in ``directory/frames``.

    ``speed`` (m/s), the initial speed, is the least colour range of the velocity
    colourings; ``gravity`` (m/s^2, or None) says where up is; ``color`` is one of
    :data:`rwall_fem.output.coloring.COLORS` or a cell field of the internal force;
    ``parts``, the names of the parts of a body of ``[[part]]`` (the ``part`` colouring);
    ``view``: the scene's [output.view] (:class:`rwall_fem.scene.view.ViewSpec`), or
    None, stored with the body for the renderer; ``contact``: the run's
    :class:`~rwall_fem.output.contact_loads.ContactLoads` when the frames show the contact
    pressure (computed at the frames only).
    """

    def __init__(
        self,
        directory: Path,
        *,
        count: int,
        end_time: float,
        V,
        walls,
        speed: float,
        gravity=None,
        color: str = "normal_velocity",
        parts: tuple[str, ...] = (),
        view=None,
        contact=None,
    ):
        self.steps = Times(count, end_time)
        self.directory = Path(directory)
        self.data = self.directory / "frames" / "data"
        self.comm = V.mesh.comm
        self.walls, self.color, self.parts, self.view = walls, color, tuple(parts), view
        self.contact = contact
        self._field = fem.Function(V)
        self._count = 0
        self._failed = False  # a frame could not be written (rank 0): no more are
        self._worker: RenderWorker | None = None  # the renderer beside the loop (rank 0)
        self._beside = self.comm.rank == 0 and wanted(self.comm.size)  # it is to be started
        topology, cell_types, points = _compat.vtk_mesh(V)
        mesh = self._gather((np.asarray(topology), np.asarray(cell_types), np.asarray(points)))
        self._mesh = mesh
        self._speed = speed
        self._gravity = np.zeros(3) if gravity is None else np.asarray(gravity, float)

    def _gather(self, local):
        pieces = self.comm.gather(local, root=0)
        if self.comm.rank != 0:
            return None
        topologies, types, points, offset = [], [], [], 0
        for topology, cell_types, x in pieces:
            # VTK's cell array is [n, i0, .., in-1, n, ...]: shift the indices only.
            topology = topology.reshape(len(cell_types), -1).copy()
            topology[:, 1:] += offset
            topologies.append(topology.ravel())
            types.append(cell_types)
            points.append(x)
            offset += len(x)
        return np.concatenate(topologies), np.concatenate(types), np.concatenate(points)

    def _nodal(self, values: np.ndarray) -> np.ndarray | None:
        f = self._field
        f.x.array[: values.size] = values.ravel()
        f.x.scatter_forward()
        gathered = self.comm.gather(f.x.array.reshape(-1, 3).copy(), root=0)
        return None if gathered is None else np.concatenate(gathered)

    def _cells(self, values: np.ndarray) -> np.ndarray | None:
        """Values on the owned cells of every rank, in the order of the gathered mesh."""
        gathered = self.comm.gather(np.asarray(values, dtype=float), root=0)
        return None if gathered is None else np.concatenate(gathered)

    def due(self, s) -> bool:
        return self.steps.due(s)

    def _save_mesh(self) -> None:
        try:
            self.data.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise OutputError(f"{self.data}: cannot be made ({err.strerror})") from None
        for stale in [*self.data.glob("frame_*.npz"), *self.data.parent.glob("frame_*.png")]:
            stale.unlink()  # a previous run into the same directory
        walls_info = [{"kind": w.shape.kind, **w.shape.parameters()} for w in self.walls]
        topology, cell_types, points = self._mesh
        self._save(
            "mesh.npz",
            topology=topology,
            cell_types=cell_types,
            points=points,
            speed=self._speed,
            gravity=self._gravity,
            walls=json.dumps(walls_info),
            **({"parts": json.dumps(self.parts)} if self.parts else {}),
            **({"view": json.dumps(view_to_json(self.view))} if self.view else {}),
        )

    def record(self, sim, s) -> None:
        self.steps.taken(s)
        u, v = self._nodal(s.u), self._nodal(s.v)
        cells = {f"cell_{k}": self._cells(a) for k, a in sim.internal.cell_fields(s).items()}
        erosion = getattr(sim.internal, "erosion", None)
        if erosion is not None:  # the nodes no live cell holds, drawn as points
            flags = np.zeros_like(s.u)
            flags[erosion.detached] = 1.0
            detached = self._nodal(flags)
            cells["detached"] = None if detached is None else detached[:, 0]
        if self.contact is not None:
            values = np.zeros_like(s.u)
            values[:, 0] = self.contact.pressure(s)
            pressure = self._nodal(values)
            cells["contact_pressure"] = None if pressure is None else pressure[:, 0]
        if self.comm.rank == 0 and not self._failed:
            try:
                if not self._count:
                    self._save_mesh()
                offsets = np.array([w.motion.offset for w in self.walls]).reshape(-1, 3)
                name = f"frame_{self._count:04d}.npz"
                self._save(name, t=s.t, u=u, v=v, offsets=offsets, **cells)
                if self._worker is None and self._beside:
                    self._beside = False  # one try: a renderer started after the loop else
                    with contextlib.suppress(OSError):  # no process to be had
                        self._worker = RenderWorker(self.directory, self.color)
                if self._worker is not None:
                    self._worker.send(name)
            except OutputError as err:  # the history ends the run on every rank
                self._failed = True
                sim.history.write_failed(err)
        self._count += 1

    def _save(self, name: str, **arrays) -> None:
        """Write ``frames/data/<name>``; OutputError naming it, and no cut file left, when
        it cannot be written (a full disk)."""
        path = self.data / name
        try:
            with whole(path) as partial:
                np.savez(partial, **arrays)
        except OSError as err:
            raise OutputError(f"{path}: cannot be written ({err.strerror})") from None

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """How many frames are stored, and the next time to store one."""
        return {"frames": np.array(self._count), "next": np.array(self.steps.next)}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Continue the numbering; frames stored after the checkpoint are removed."""
        self._count, error = int(arrays["frames"]), None
        self.steps.next = int(arrays["next"])
        if self.comm.rank == 0:
            if self._count and not (self.data / "mesh.npz").is_file():
                error = f"{self.data / 'mesh.npz'}: missing, and the checkpoint has frames"
            for later in self.data.glob("frame_*.npz"):
                if int(later.stem.removeprefix("frame_")) >= self._count:
                    later.unlink()
        error = self.comm.bcast(error, root=0)
        if error:
            raise ValueError(error)

    def close(self, sim) -> None:
        """Draw the stored frames into PNGs and ``animation.gif`` (rank 0): the worker draws
        them if there is one and it is well, else a renderer started now."""
        if self.comm.rank != 0:
            return
        worker, self._worker = self._worker, None
        if not self._count or self._failed:
            if worker is not None:
                worker.abandon()
            return
        if worker is not None:
            code, messages = worker.finish()
            if code == 0:
                return
            last = (messages.strip().splitlines() or [f"exit code {code}"])[-1]
            print(f"rwall-fem: warning: the renderer beside the run failed ({last}); drawing "
                  "the frames again", file=sys.stderr)  # fmt: skip
        result = subprocess.run(
            renderer_command(self.directory, self.color),
            env=renderer_env(),
            capture_output=True,
            text=True,
        )
        if result.returncode != 0:
            lines = result.stderr.strip().splitlines() or ["no message"]
            error = OutputError(f"rendering the frames into {self.data.parent} failed: {lines[-1]}")
            error.add_note(result.stderr[-2000:])  # the renderer's traceback
            raise error
