"""Shared helpers: scenes as dictionaries, run in-process on a chosen communicator.

The suite runs serially and under ``mpirun -n 2``; a test that runs a scene
uses ``MPI.COMM_WORLD`` unless it says otherwise, and every rank asserts. A test
marked ``@pytest.mark.serial`` runs on one rank only (it starts subprocesses, or
measures one rank); under ``mpirun`` it is skipped.

- ``unit/``: one module against hand values or closed forms;
- ``verification/``: runs against independent references (wave theory, closed forms);
- ``contract/``: what a user relies on (outputs, command line, refusals, the wheel);
- ``hard/``: numerically hard scenes that must stay stable (``--full``: finer).
"""

import copy
import math
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.output.wall_table import WALL_COLUMNS
from rwall_fem.study.cases import SOFT, STEEL_NU0

COLUMN = {name: i for i, name in enumerate(WALL_COLUMNS)}  # columns of walls.csv

# A small scene file for the command-line tests: a steel bar onto a fixed plane.
SCENE = """
[run]
end_time = 2e-5
[mesh]
shape = "bar"
size = [0.004, 0.004, 0.02]
element_size = 0.002
[material]
model = "linear_elastic"
density = 7850.0
young = 210e9
poisson = 0.3
[initial]
velocity = [0.0, 0.0, -5.0]
[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal_point = [0.0, 0.0, 1.0]
[output]
frames = 3
"""


def mpi_launch(ranks: int) -> tuple[list[str], dict]:
    """The command prefix and environment that start ``ranks`` ranks of this leg's Python:
    the MPICH ``mpiexec`` beside it (the PyPI leg), else Open MPI's ``mpirun`` (Debian);
    the environment is this one without the variables of the session's own MPI job."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    beside = Path(sys.executable).parent / "mpiexec"
    if beside.exists():
        return [str(beside), "-n", str(ranks)], env | {"UCX_TLS": "self,sm,tcp"}
    launcher = [shutil.which("mpirun") or "mpirun", "--allow-run-as-root", "--oversubscribe"]
    return [*launcher, "-n", str(ranks)], env | {"OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


def bar_scene(
    *,
    elements=40,
    h=1e-3,
    axis=(0.0, 0.0, 1.0),
    cell="hexahedron",
    speed=10.0,
    wall=True,
    end_time=None,
    gap=0.0,
):
    """A nu = 0 steel bar of ``elements`` layers along ``axis`` moving at ``speed`` toward a
    fixed plane whose normal is ``axis``; the bar's lower face is ``gap`` (m) above the plane."""
    L = elements * h
    c = math.sqrt(STEEL_NU0["young"] / STEEL_NU0["density"])
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    origin = list(gap * axis)
    raw = {
        "run": {"end_time": end_time or (gap / speed + 3.0 * L / c), "dt_scale": 0.9},
        "mesh": {
            "shape": "bar",
            "origin": origin,
            "size": [h, h, L],
            "axis": list(axis),
            "element_size": h,
            "cell": cell,
        },
        "material": dict(STEEL_NU0),
        "initial": {"velocity": list(-speed * axis)},
        "output": {"frames": 0, "plot": False},
    }
    if wall:
        raw["wall"] = [{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": list(axis)}]
    return raw


def pytest_addoption(parser):
    parser.addoption(
        "--full", action="store_true", help="run tests/hard at twice the resolution (slow)"
    )


def pytest_configure(config):
    config.addinivalue_line("markers", "serial: runs on one rank only, skipped under mpirun")


def pytest_collection_modifyitems(config, items):
    if MPI.COMM_WORLD.size == 1:
        return
    skip = pytest.mark.skip(reason="serial only: starts subprocesses or measures one rank")
    for item in items:
        if item.get_closest_marker("serial"):
            item.add_marker(skip)


@pytest.fixture
def refine(request) -> int:
    """Refinement factor of the hard cases: 1, or 2 with --full."""
    return 2 if request.config.getoption("--full") else 1


@pytest.fixture
def shared_dir(tmp_path_factory):
    """A directory that every rank of COMM_WORLD sees (rank 0's temporary path)."""
    path = tmp_path_factory.mktemp("run") if MPI.COMM_WORLD.rank == 0 else None
    return MPI.COMM_WORLD.bcast(path, root=0)


def run(raw, directory, comm=MPI.COMM_WORLD):
    """Run the scene ``raw`` (a dict) into ``directory``; returns the finished Simulation."""
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)
    sim.run()
    return sim


class Probe:
    """Recorder that samples the body's centre of mass (m) and mean velocity (m/s) each step.

    The velocity is the mid-step v^{n-1/2}; ``distances`` collects, per wall, the
    smallest signed distance of its secondary nodes at the start of each step (on a
    parallelogram, of those facing it).
    """

    def __init__(self, sim):
        self.comm = sim.comm
        self.mass = self.comm.allreduce(float(sim.state.mass.sum()))
        self.walls = sim.walls
        self.t, self.x, self.v, self.distances = [], [], [], []
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        m = s.mass[:, None]
        local = np.concatenate([np.sum(m * (s.X + s.u), axis=0), np.sum(m * s.v, axis=0)])
        total = self.comm.allreduce(local) / self.mass
        self.t.append(s.t)
        self.x.append(total[:3])
        self.v.append(total[3:])
        nearest = []
        for w in self.walls:
            x = s.X[w.nodes] + s.u[w.nodes]
            offset = w.motion.offset - s.dt * w.motion.velocity  # the wall has moved on
            d = w.shape.distance(x, offset)
            # Beside a finite wall a node may be anywhere: count those facing it only.
            d = np.where(w.shape.inside_patch(x, offset), d, np.inf)
            nearest.append(d.min(initial=np.inf))
        nearest_everywhere = np.empty(len(nearest))
        self.comm.Allreduce(np.array(nearest, dtype=float), nearest_everywhere, op=MPI.MIN)
        self.distances.append(nearest_everywhere)

    def close(self, sim):
        self.t, self.x, self.v = map(np.array, (self.t, self.x, self.v))
        self.distances = np.array(self.distances)


class StopAt:
    """Recorder that, at ``step``, asks the run to stop as SIGTERM does."""

    def __init__(self, step):
        self.step = step

    def due(self, s):
        return s.step == self.step

    def record(self, sim, s):
        sim.stop_requests.add("SIGTERM")

    def close(self, sim):
        pass


def run_probed(raw, directory, comm=MPI.COMM_WORLD):
    """Like :func:`run`, with a :class:`Probe` attached; returns (simulation, probe)."""
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)
    probe = Probe(sim)
    sim.run()
    return sim, probe


def block_scene(
    *,
    size=0.01,
    h=0.005,
    origin=(0.0, 0.0, 0.0),
    end_time=0.2,
    gravity=None,
    wall=None,
    velocity=(0.0, 0.0, 0.0),
    cell="hexahedron",
):
    """A soft cube (c_p about 37 m/s, so dt is about 1e-4 s) with its lowest corner at
    ``origin``, on the walls ``wall`` (a list of wall tables)."""
    raw = {
        "run": {"end_time": end_time},
        "mesh": {
            "shape": "bar",
            "origin": list(origin),
            "size": [size] * 3,
            "element_size": h,
            "cell": cell,
        },
        "material": dict(SOFT),
        "initial": {"velocity": list(velocity)},
        "wall": wall or [],
        "output": {"plot": False},
    }
    if gravity is not None:
        raw["gravity"] = {"acceleration": list(gravity)}
    return raw
