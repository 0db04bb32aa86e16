"""Size limits: what a scene will cost is estimated before meshing (``check`` prints it)
and ``run`` refuses a scene above ``run.max_cells``, ``run.max_steps`` or
``run.max_frames`` in one line that gives the estimate and the way on; ``--lift-limits``
lifts them. Before: a 1 m cube at 1 mm meshed for minutes at 3 GB, ``end_time = 1e9``
planned 2.8e15 steps, ``frames = 1e8`` made ``check`` take a minute.

The command runs in-process on every rank of the session (each rank gets the exit code,
rank 0 prints).
"""

import re

import pytest
from conftest import SCENE
from mpi4py import MPI

from rwall_fem import parse_scene
from rwall_fem.cli import main
from rwall_fem.estimate import estimate
from rwall_fem.meshing import body_mesh
from rwall_fem.output.schedule import Times

STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3}


@pytest.fixture
def scene_file(shared_dir):
    path = shared_dir / "scene.toml"
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(SCENE)
    MPI.COMM_WORLD.Barrier()
    return path


def one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    if MPI.COMM_WORLD.rank != 0:
        return ""
    assert len(err) == 1, err
    return err[0]


def test_check_prints_the_estimate_before_meshing(scene_file, capsys):
    assert main(["check", str(scene_file)]) == 0
    out = capsys.readouterr().out
    if MPI.COMM_WORLD.rank == 0:
        # The bar is 4 x 4 x 20 mm at 2 mm: 2 x 2 x 10 hexahedra.
        estimate_line = out.index("estimate before meshing: about 40 hexahedron cells")
        assert estimate_line < out.index("mesh: 40 hexahedron cells")
        assert "steps of" in out and "3 frames" in out


@pytest.mark.parametrize(
    "overrides, message",
    [
        (["run.max_cells=10"], "run.max_cells: the mesh would have about 40 hexahedron cells"),
        (["run.max_steps=50"], "run.max_steps: run.end_time = 2e-05 s takes about "),
        (["output.frames=1001"], "run.max_frames: output.frames = 1001 is more than"),
        (["output.fields=5", "run.max_frames=4"], "run.max_frames: output.fields = 5 is more"),
    ],
)
def test_run_refuses_a_scene_above_a_limit_before_meshing(
    overrides, message, scene_file, shared_dir, capsys
):
    out = shared_dir / "out"
    sets = [item for o in overrides for item in ("--set", o)]
    assert main(["run", str(scene_file), "--out", str(out), *sets]) == 2
    line = one_line(capsys)
    if MPI.COMM_WORLD.rank == 0:
        assert message in line and line.endswith("or pass --lift-limits to rwall-fem")
        assert "mesh:" not in capsys.readouterr().out  # nothing was meshed
        assert not out.exists()


def test_the_count_after_meshing_is_checked_too(scene_file, shared_dir, capsys):
    """The estimate (slightly fewer steps than the stable step gives) passes the limit;
    the steps counted with the stable step do not."""
    out = shared_dir / "out"
    assert main(["run", str(scene_file), "--out", str(out), "--set", "run.max_steps=70"]) == 2
    line = one_line(capsys)
    if MPI.COMM_WORLD.rank == 0:
        steps = int(re.search(r"takes (\d+) steps", line).group(1))
        assert steps > 70 and "more than run.max_steps = 70" in line


def test_lift_limits_runs_the_scene(scene_file, shared_dir):
    out = shared_dir / "out"
    args = ["run", str(scene_file), "--out", str(out), "--quiet", "--set", "run.max_cells=10"]
    args += ["--set", "output.frames=0"]
    assert main([*args, "--lift-limits"]) == 0


@pytest.mark.parametrize(
    "mesh",
    [
        {"shape": "bar", "size": [0.01, 0.01, 0.04], "element_size": 1e-3,
         "refine_point": [0.005, 0.005, 0.0], "refine_size": 1e-4},
        {"shape": "bar", "size": [0.01, 0.01, 0.04], "element_size": 1e-3,
         "refine_point": [0.005, 0.005, 0.0], "refine_size": 1e-4, "cell": "tetrahedron"},
        {"shape": "round_bar", "radius": 0.005, "length": 0.01, "element_size": 5e-4,
         "refine_point": [0.0, 0.005, 0.0], "refine_size": 5e-5},
        {"shape": "round_bar", "radius": 0.005, "length": 0.01, "element_size": 1e-3,
         "cell": "tetrahedron"},
        {"shape": "plate", "size": [0.05, 0.03, 0.002], "element_size": 1e-3, "layers": 3},
        {"shape": "plate_with_hole", "size": [0.05, 0.03, 0.002], "hole_radius": 0.005,
         "element_size": 1e-3, "refine_point": [0.03, 0.015, 0.002], "refine_size": 1e-4},
    ],
)  # fmt: skip
def test_cell_estimates_hold_to_25_percent(mesh):
    """Against the count of the mesh gmsh makes (the factors were measured on others)."""
    scene = parse_scene({"run": {"end_time": 1e-5}, "mesh": mesh, "material": STEEL})
    cells = body_mesh(MPI.COMM_WORLD, scene.mesh).num_cells
    assert estimate(scene).cells == pytest.approx(cells, rel=0.25)


def test_parts_estimate_the_step_of_their_fastest_material():
    """A scene of [[part]] without [material]: the part with the fastest waves sets the
    estimated step, as one of that material alone would."""
    mesh = {"shape": "bar", "size": [0.004, 0.004, 0.02], "element_size": 0.002,
            "front_length": 0.006}  # fmt: skip
    soft = STEEL | {"young": 21e9}
    parts = parse_scene({"run": {"end_time": 1e-5}, "mesh": mesh, "part": [
        {"name": "rod", "volumes": ["body"], "material": soft},
        {"name": "nose", "volumes": ["front"], "material": STEEL}]})  # fmt: skip
    alone = parse_scene({"run": {"end_time": 1e-5}, "mesh": mesh, "material": STEEL})
    assert estimate(parts).steps == estimate(alone).steps


def test_times_sample_the_first_step_at_or_after_each_time():
    """Outputs at times: due at the first step at or after each requested time, once per
    step however many times it passes, the rest at the last step; an evenly stepped run
    gets them exactly where they are asked."""

    class Step:
        def __init__(self, step, t, dt, last=False):
            self.step, self.t, self.dt, self.last = step, t, dt, last

    def sampled(times, steps):
        taken = []
        for s in steps:
            if times.due(s):
                times.taken(s)
                taken.append(s.step)
        return taken

    dt = 1e-3
    even = [Step(n, n * dt, dt, last=n == 10) for n in range(11)]
    assert sampled(Times(6, 10 * dt), even) == [0, 2, 4, 6, 8, 10]
    assert sampled(Times(1, 10 * dt), even) == [0]
    growing = [Step(n, 0.5 * n * n * dt, n * dt, last=n == 5) for n in range(6)]  # t: 0..12.5
    # times 0, 2.5, 5, 7.5, 10, 12.5 (x dt) -> steps 0, 3 (t = 4.5), 4 (8), 5 (12.5, last)
    assert sampled(Times(6, 12.5 * dt), growing) == [0, 3, 4, 5]
    short = [Step(n, n * dt, dt, last=n == 3) for n in range(4)]
    times = Times(10**8, 3 * dt)
    assert sampled(times, short) == [0, 1, 2, 3] and times.next == 10**8
