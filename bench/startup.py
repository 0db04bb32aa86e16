"""Start-up of ``rwall-fem run`` split by stage (run by bench/bench.py in a fresh process).

The command line's own entry point (:func:`rwall_fem.cli.main`) runs a 10k-cell scene of
two steps; the functions that ``rwall_fem.build`` calls for each stage are wrapped with
timers first, so the stages are those of a real launch:

- Python: from the launch (``--launched``, the parent's wall clock) to this file's
  first line;
- imports: mpi4py, petsc4py, dolfinx, then rwall_fem (the CLI and the build modules);
- scene: reading and validating the TOML;
- meshing: gmsh and the distribution of the mesh (``body_mesh``);
- space and mass: the vector function space, its coordinates, the lumped mass (a form
  compiled by FFCx, cached per user);
- kernels: loading the compiled element kernels (compiling them on a cold cache);
- stable step: SLEPc on the kernels (``critical_time_step``) and the edge estimate;
- rest of the set-up: the element force, walls, history, checkpoints;
- first step: from the start of the time loop to the end of step 0.

Prints one JSON line on rank 0.
"""

import time

T_FIRST_LINE = time.time()
P_FIRST_LINE = time.perf_counter()

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("scene")
p.add_argument("--out", required=True)
p.add_argument("--launched", type=float, required=True, help="time.time() at the launch")
a = p.parse_args()

marks = {}


def mark(name, t0):
    marks[name] = marks.get(name, 0.0) + time.perf_counter() - t0


t0 = time.perf_counter()
from mpi4py import MPI  # noqa: E402

mark("import mpi4py", t0)
t0 = time.perf_counter()
from petsc4py import PETSc  # noqa: E402, F401

mark("import petsc4py", t0)
t0 = time.perf_counter()
import dolfinx  # noqa: E402, F401
import dolfinx.fem.petsc  # noqa: E402, F401

mark("import dolfinx", t0)
t0 = time.perf_counter()
import rwall_fem.build as build  # noqa: E402
import rwall_fem.cli as cli  # noqa: E402
import rwall_fem.elements as elements  # noqa: E402
import rwall_fem.mechanics as mechanics  # noqa: E402
import rwall_fem.scene as scene_module  # noqa: E402
import rwall_fem.solver as solver  # noqa: E402
from rwall_fem import _compat  # noqa: E402

mark("import rwall_fem", t0)


def timed(module, name, stage):
    inner = getattr(module, name)

    def wrapper(*args, **kwargs):
        t = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            mark(stage, t)

    setattr(module, name, wrapper)


timed(scene_module, "load_scene", "scene")
timed(build, "body_mesh", "meshing")
timed(_compat, "model_to_mesh", "meshing: distribution (DOLFINx)")
timed(_compat, "vector_space", "space and mass")
timed(mechanics, "lumped_mass", "space and mass")  # imported by body at its call
timed(elements, "load", "kernels")
timed(build, "critical_time_step", "stable step: SLEPc")
timed(build, "shortest_edge", "stable step: edges")
timed(build, "build_simulation", "set-up (all)")

first_step = {}
run = solver.Simulation.run


def timed_run(self):
    first_step["loop_start"] = time.perf_counter()
    recorder = _FirstStep()
    self.recorders.append(recorder)
    status = run(self)
    first_step["end_of_step_0"] = recorder.at
    return status


class _FirstStep:
    """Notes the time at which step 1 starts: step 0 is then done."""

    at = None

    def due(self, s):
        return s.step == 1

    def record(self, sim, s):
        self.at = time.perf_counter()

    def close(self, sim):
        pass


solver.Simulation.run = timed_run
t0 = time.perf_counter()
code = cli.main(["run", a.scene, "--out", a.out, "--quiet"])
end = time.perf_counter()
if code != 0:
    sys.exit(code)
setup_all = marks.pop("set-up (all)")
staged = sum(
    marks.get(k, 0.0)
    for k in ("meshing", "space and mass", "kernels", "stable step: SLEPc", "stable step: edges")
)
record = {
    "python": T_FIRST_LINE - a.launched,
    **{k: v for k, v in marks.items()},
    "rest of set-up": setup_all - staged,
    "first step": first_step["end_of_step_0"] - first_step["loop_start"],
    "launch to first step": T_FIRST_LINE - a.launched + first_step["end_of_step_0"] - P_FIRST_LINE,
    "launch to exit of main": T_FIRST_LINE - a.launched + end - P_FIRST_LINE,
}
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps(record))
