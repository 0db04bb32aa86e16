"""The run contract: outputs, the command line, and refusals of bad input."""

import csv
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SCENE, bar_scene, run
from mpi4py import MPI

from rwall_fem import SceneError, parse_scene
from rwall_fem.output.wall_table import WALL_COLUMNS


def test_outputs_of_a_run(shared_dir):
    raw = bar_scene(elements=8, h=2e-3, cell="tetrahedron")
    raw["output"] = {"frames": 3, "fields": 2, "history_interval": 5}
    sim = run(raw, shared_dir)
    if MPI.COMM_WORLD.rank == 0:
        out = Path(shared_dir)
        summary = json.loads((out / "summary.json").read_text())
        for key in (
            "dolfinx_version",
            "element",
            "ranks",
            "cells",
            "nodes",
            "steps",
            "dt",
            "end_time",
            "wall_seconds",
            "effects",
            "mass",
            "initial_momentum",
            "final_momentum",
            "version",
            "git_hash",
            "planned_steps",
            "time",
            "warnings",
        ):
            assert key in summary
        assert summary["ranks"] == MPI.COMM_WORLD.size
        assert summary["steps"] == summary["planned_steps"] == sim.planned_steps
        assert summary["warnings"] == []
        assert set(summary["energy"]) == {
            "initial",
            "kinetic",
            "internal",
            "external_work",
            "wall_work",
            "max_balance_error",
        }
        assert set(summary["walls"][0]) >= {"kind", "impulse", "first_contact", "last_contact"}
        rows = list(csv.DictReader(open(out / "energy.csv")))
        assert list(rows[0]) == [
            "time",
            "kinetic",
            "internal",
            "external_work",
            "wall_work",
            "balance_error",
            "total_energy",
            "energy_error_percent",
            "dt",
        ]
        for row in rows:  # GLSTAT's total energy, Radioss's energy error %, the step's dt
            assert float(row["total_energy"]) == float(row["kinetic"]) + float(row["internal"])
            assert float(row["energy_error_percent"]) == 100 * float(row["balance_error"])
            assert float(row["dt"]) == sim.state.dt
        # every 5th step and the last one
        assert len(rows) == sim.planned_steps // 5 + 1 + (sim.planned_steps % 5 > 0)
        walls = list(csv.DictReader(open(out / "walls.csv")))
        columns = ["time", "wall", *(f"{q}_{c}" for q in ("force", "impulse") for c in "xyz")]
        assert list(walls[0])[:8] == columns
        assert list(walls[0]) == WALL_COLUMNS
        assert {"contacts", "normal_force_x", "tangential_impulse_z", "velocity_z"} <= set(walls[0])
        frames = sorted((out / "frames").glob("frame_*.png"))
        assert len(frames) == 3
        assert (out / "animation.gif").stat().st_size > 0
        if importlib.util.find_spec("imageio_ffmpeg"):  # `make test` installs it (extra mp4)
            assert (out / "animation.mp4").stat().st_size > 0
        assert (out / "histories.png").stat().st_size > 0
        assert "rendering 3 frames after the time loop" in (out / "run.log").read_text()
        xdmf = (out / "fields.xdmf").read_text()
        for name in ("displacement", "velocity", "von_mises_stress"):
            assert xdmf.count(f'<Attribute Name="{name}"') == 2  # two snapshots of each


def test_dt_above_stable_limit_is_refused(shared_dir):
    raw = bar_scene(elements=4)
    raw["run"]["dt"] = 1e-6  # h / c = 1.9e-7 s
    with pytest.raises(SceneError, match=r"run\.dt: 1e-06 s is above the stable limit"):
        run(raw, shared_dir)


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("run.dt_scale", 1.5, r"run\.dt_scale: must be a finite number in \(0, 1\]"),
        ("run.end_time", 0.0, r"run\.end_time: must be a finite number in \(0, inf\)"),
        ("material.poisson", 0.5, r"material\.poisson: .* in \(-1, 0\.5\)"),
        ("material.densty", 1.0, r"unknown key \(did you mean 'density'\?\)"),
        ("mesh.cell", "prism", r"mesh\.cell: must be one of 'hexahedron', 'tetrahedron'"),
        ("mesh.size", [1.0, 0.0, 1.0], r"mesh\.size: must be 3 positive lengths"),
        ("wall.0.normal_point", [0.0, 0.0, 0.0], r"wall\[0\]\.normal_point: must differ"),
        ("wall.0.kind", "cone", r"wall\[0\]\.kind: must be one of 'plane', 'cylinder'"),
        ("wall.0.slide", "sticky", r"wall\[0\]\.slide: must be one of 'free', 'tied', 'friction'"),
        ("wall.0.friction", 0.3, r"wall\[0\]\.friction: needs slide = 'friction'"),
        ("wall.0.diameter", 1.0, r"wall\[0\]\.diameter: is not a key of a plane wall"),
        ("wall.0.point", [0.0, float("nan"), 0.0], r"wall\[0\]\.point: must be 3 finite"),
        ("wall.0.motion", {"mass": -1.0, "velocity": [0, 0, 1]}, r"motion\.mass: must be"),
        ("wall.0.motion", {"velocity": [[0, 0, 0, 1], [0, 1, 0, 0]]}, r"increasing t"),
        ("wall.0.secondary", {"search": 1.0}, r"did you mean 'search_distance'"),
        ("mesh.noise", {"amplitude": -1e-6}, r"mesh\.noise\.amplitude: must be a finite"),
        ("gravity", [0, 0, -9.81], r"gravity: must be a table"),
    ],
)
def test_bad_scenes_name_the_key(key, value, message):
    raw = bar_scene(elements=4)
    section, *rest = key.split(".")
    target = raw if not rest else raw[section] if len(rest) == 1 else raw[section][int(rest[0])]
    target[rest[-1] if rest else section] = value
    with pytest.raises(SceneError, match=message):
        parse_scene(raw, source="bad.toml")


@pytest.mark.parametrize(
    "wall, message",
    [
        (
            {"kind": "cylinder", "point": [0, 0, 0], "axis_point": [0, 0, 1], "diameter": 0.0},
            r"wall\[0\]\.diameter: must be a finite number in \(0, inf\)",
        ),
        (
            {"kind": "cylinder", "point": [1, 1, 1], "axis_point": [1, 1, 1], "diameter": 1.0},
            r"wall\[0\]\.axis_point: must differ from 'point'",
        ),
        ({"kind": "sphere", "point": [0, 0, 0]}, r"wall\[0\]\.diameter: missing"),
        (
            {
                "kind": "parallelogram",
                "point": [0, 0, 0],
                "corner1": [1, 0, 0],
                "corner2": [3, 0, 0],
            },
            r"wall\[0\]\.corner2: sides .* are parallel",
        ),
        (
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal_point": [0, 0, 1],
                "slide": "friction",
                "friction": 0.2,
                "friction_filter": {"steps": 3},
            },
            r"friction_filter\.steps: .*\[6\.28",
        ),
        (
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal_point": [0, 0, 1],
                "slide": "friction",
                "friction": 0.2,
                "friction_filter": {"steps": 10, "coefficient": 0.5},
            },
            r"give exactly one of coefficient, steps, frequency",
        ),
    ],
)
def test_bad_walls_name_the_field(wall, message):
    raw = bar_scene(elements=4)
    raw["wall"] = [wall]
    with pytest.raises(SceneError, match=message):
        parse_scene(raw, source="bad.toml")


def test_friction_filter_frequency_above_one_step_is_refused(shared_dir):
    raw = bar_scene(elements=4)
    raw["wall"][0] |= {"slide": "friction", "friction": 0.2, "friction_filter": {"frequency": 1e9}}
    with pytest.raises(SceneError, match=r"friction_filter\.frequency: gives alpha = .* must be"):
        run(raw, shared_dir)


def _cli(*args, cwd):
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    return subprocess.run(
        [sys.executable, "-m", "rwall_fem", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.serial
def test_command_line_run_with_override(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    result = _cli(
        "run",
        "scene.toml",
        "--out",
        "out",
        "--set",
        "initial.velocity=[0, 0, -2]",
        "--set",
        "output.frames=0",
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["initial_momentum"][2] == pytest.approx(-2.0 * summary["mass"])
    assert "done:" in result.stdout


@pytest.mark.serial
@pytest.mark.parametrize(
    "args, message",
    [
        (["run", "missing.toml"], "missing.toml: scene file not found"),
        (["run", "scene.toml", "--set", "material.young=-1"], "material.young: must be"),
        (["run", "scene.toml", "--set", "wall[3].slide=free"], "index 3 does not exist"),
        (["run", "scene.toml", "--set", "run.dt=1e-3"], "run.dt: 0.001 s is above the stable"),
    ],
)
def test_command_line_bad_input_is_one_line(tmp_path, args, message):
    (tmp_path / "scene.toml").write_text(SCENE)
    result = _cli(*args, cwd=tmp_path)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.serial
def test_check_prints_what_would_run_and_writes_nothing(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    result = _cli("check", "scene.toml", "--set", "mesh.cell='tetrahedron'", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "is valid" in result.stdout and "tetrahedron cells" in result.stdout
    assert "effects: linear_elastic, wall[0]" in result.stdout
    assert "estimated wall time" in result.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml"]


@pytest.mark.serial
def test_render_draws_a_results_folder_again(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    assert _cli("run", "scene.toml", "--out", "out", "--quiet", cwd=tmp_path).returncode == 0
    for png in (tmp_path / "out" / "frames").glob("*.png"):
        png.unlink()
    result = _cli("render", "out", "--color", "displacement", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert len(list((tmp_path / "out" / "frames").glob("frame_*.png"))) == 3
    missing = _cli("render", "nowhere", cwd=tmp_path)
    assert missing.returncode == 2
    assert missing.stderr.splitlines() == ["rwall-fem: error: nowhere: no such folder"]
    empty = _cli("render", ".", cwd=tmp_path)
    assert empty.returncode == 2 and "no frame data" in empty.stderr


@pytest.mark.serial
def test_a_surface_mesh_without_a_thickness_is_refused(tmp_path):
    """A mesh file of surfaces is a body of shells: without element.thickness, one line."""
    import gmsh

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.addRectangle(0, 0, 0, 0.01, 0.01)
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(2, [1])
    gmsh.model.mesh.generate(2)
    gmsh.write(str(tmp_path / "square.msh"))
    gmsh.finalize()
    scene = SCENE.replace(
        '[mesh]\nshape = "bar"\nsize = [0.004, 0.004, 0.02]\nelement_size = 0.002',
        '[mesh]\nfile = "square.msh"',
    )
    (tmp_path / "scene.toml").write_text(scene)
    result = _cli("run", "scene.toml", cwd=tmp_path)
    assert result.returncode == 2
    assert (
        "element.thickness: missing: a mesh file of surfaces (shells) needs the shells' "
        "thickness (m)" in result.stderr
    )
    assert len(result.stderr.strip().splitlines()) == 1


def test_walls_given_as_shape_objects_equal_their_tables():
    """The Python API takes a wall as a shape object, alone or as ``shape`` beside options;
    it is validated as the table a scene file would have."""
    from rwall_fem import CylinderWall, PlaneWall

    raw = bar_scene(elements=4)
    tables = [
        {"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]},
        {"kind": "cylinder", "point": [0, 0, -1], "axis_point": [0, 1, -1], "diameter": 0.5,
         "slide": "friction", "friction": 0.3},
    ]  # fmt: skip
    objects = [
        PlaneWall([0, 0, 0], [0, 0, 2]),
        {"shape": CylinderWall([0, 0, -1], [0, 1, -1], 0.5), "slide": "friction", "friction": 0.3},
    ]
    assert parse_scene(raw | {"wall": objects}).walls == parse_scene(raw | {"wall": tables}).walls
    for wall, message in [
        ({"shape": "plane"}, r"wall\[0\]\.shape: must be a wall shape: PlaneWall"),
        ({"shape": objects[0], "kind": "plane"}, r"wall\[0\]\.kind: give either 'kind' or"),
        ({"shape": objects[0], "diameter": 1.0}, r"wall\[0\]\.diameter: is not a key of a plane"),
    ]:
        with pytest.raises(SceneError, match=message):
            parse_scene(raw | {"wall": [wall]}, source="api")


def test_the_reference_scene_uses_every_key():
    """demos/every_key.toml is a valid scene that shows every key of the schema, in use or
    commented out as an alternative."""
    import re

    from rwall_fem import load_scene
    from rwall_fem.scene.keys import keys_of
    from rwall_fem.scene.reference import tables

    path = Path(__file__).resolve().parents[2] / "demos" / "every_key.toml"
    load_scene(path)
    text = path.read_text()
    keys = set(re.findall(r"(?:^#?\s*|[{,]\s*)(\w+)\s*=", text, re.MULTILINE))
    keys |= set(re.findall(r"^(?:# )?\[\[?[\w.]*\.(\w+)\]\]?", text, re.MULTILINE))  # [a.b]
    top = set(re.findall(r"^(?:# )?\[\[?(\w+)\]\]?", text, re.MULTILINE))
    accepted = [(where, name) for where, _, cls in tables() for name in keys_of(cls)]
    missing = [
        f"{where}.{name}" if where else name
        for where, name in accepted
        if name not in (top if where == "" else keys)
    ]
    assert len({where for where, _ in accepted}) >= 12 and not missing
