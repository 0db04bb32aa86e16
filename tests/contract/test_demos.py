"""Every demo runs, at a coarse resolution, with a closed energy balance and its pictures."""

import json
import runpy
from pathlib import Path

import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, load_scene

DEMOS = Path(__file__).resolve().parents[2] / "demos"
COARSE = {  # scene -> overrides that keep it to a few seconds
    "bar_impact": ["mesh.element_size=0.005", "run.end_time=3e-5"],
    "moving_wall_crush": ["mesh.element_size=0.005", "run.end_time=1e-4"],
    "friction_slide": ["mesh.element_size=0.01", "run.end_time=0.1"],
    "plate_on_cylinder": ["mesh.element_size=0.004", "run.end_time=0.005"],
    "plate_on_sphere": ["mesh.element_size=0.003", "run.end_time=0.005"],
    "bar_on_parallelogram_edge": ["mesh.element_size=0.005", "run.end_time=2e-4"],
    "every_key": ["mesh.element_size=0.005", "run.end_time=5e-5"],
    "taylor_rod": ["mesh.element_size=0.0008", "run.dt_scale=0.1", "run.end_time=1e-5"],
    "taylor_johnson_cook": ["mesh.element_size=0.001", "run.end_time=1e-5"],
    "perforation_weldox": ["run.end_time=2e-5"],  # its mesh file's 2 mm: the first contact
    "copper_nosed_striker": ["mesh.element_size=0.001", "run.end_time=1e-5"],
    "tube_crush": ["mesh.element_size=0.01", "run.end_time=3e-4"],
}


def test_every_scene_has_a_coarse_setting():
    assert sorted(p.stem for p in DEMOS.glob("*.toml")) == sorted(COARSE)


# Pictures cost a few seconds each (a separate process draws them): the serial run checks
# them, the parallel run checks the physics and test_run_contract the gathered frames.
PICTURES = MPI.COMM_WORLD.size == 1


@pytest.mark.parametrize("name", sorted(COARSE))
def test_demo_scene(name, shared_dir):
    frames = 2 if PICTURES else 0
    scene = load_scene(DEMOS / f"{name}.toml", [*COARSE[name], f"output.frames={frames}"])
    sim = build_simulation(scene, MPI.COMM_WORLD, shared_dir)
    assert sim.run() == "done"
    # Round-off for linear elasticity; O(dt^2) for the neo-Hookean sheets (1e-3 seen).
    assert sim.history.summary["energy"]["max_balance_error"] < 5e-3
    if PICTURES:
        out = Path(shared_dir)
        assert len(list((out / "frames").glob("frame_*.png"))) == 2
        assert (out / "animation.gif").is_file() and (out / "histories.png").is_file()


# Python demo -> (frames it draws, bound on its balance error: round-off for linear
# elasticity, O(dt^2) for the neo-Hookean sheet, 8e-4 seen).
SCRIPTS = {
    "demo_bar_impact": (12, 1e-10),
    "demo_plate_on_cylinder": (10, 2e-3),
    "demo_taylor_rod": (0, 1e-10),
    "demo_perforation_weldox": (0, 1e-10),
}


def test_every_script_is_tested():
    assert sorted(p.stem for p in DEMOS.glob("demo_*.py")) == sorted(SCRIPTS)


@pytest.mark.parametrize("name", sorted(SCRIPTS))
def test_python_demo(name, shared_dir, monkeypatch):
    frames, balance = SCRIPTS[name]
    monkeypatch.chdir(shared_dir)
    monkeypatch.setenv("TAYLOR_ELEMENT_SIZE", "0.8e-3")  # the Taylor rod's quick look
    monkeypatch.setenv("PERFORATION_ELEMENT_SIZE", "6e-3")  # the perforation's, at one speed
    monkeypatch.setenv("PERFORATION_SPEEDS", "400")
    runpy.run_path(str(DEMOS / f"{name}.py"), run_name="__main__")
    if MPI.COMM_WORLD.rank == 0:
        out = Path(shared_dir) / "results" / name
        for path in out.rglob("summary.json"):  # one per run of the demo
            summary = json.loads(path.read_text())
            assert summary["status"] == "done"
            assert summary["energy"]["max_balance_error"] < balance
        assert any(out.rglob("summary.json"))
        assert len(list((out / "frames").glob("frame_*.png"))) == frames
