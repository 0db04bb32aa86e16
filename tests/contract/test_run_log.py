"""What a Radioss or LS-DYNA user reads after a run: ``run.log`` (like 0000.out/0001.out
or d3hsp), cycle lines on stderr when it is not a terminal, the code's version and git
commit in summary.json, and no compiler chatter."""

import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import dolfinx
import pytest
from conftest import SCENE
from mpi4py import MPI

import rwall_fem
from rwall_fem import load_scene, parse_scene
from rwall_fem.cli import main

REPOSITORY = Path(rwall_fem.__file__).resolve().parents[1]


def checkout_commit() -> str | None:
    """The commit of the checkout the package runs from, asked of git here (None: not one)."""
    if not (REPOSITORY / ".git").exists():
        return None
    head = subprocess.run(["git", "-C", str(REPOSITORY), "rev-parse", "HEAD"],
                          capture_output=True, text=True)  # fmt: skip
    return head.stdout.strip() or None


def test_run_log_holds_versions_scene_mesh_cycles_and_figures(shared_dir):
    scene_file, out = shared_dir / "scene.toml", shared_dir / "out"
    if MPI.COMM_WORLD.rank == 0:
        scene_file.write_text(SCENE.replace("frames = 3", "frames = 0\nprint_interval = 10"))
    MPI.COMM_WORLD.Barrier()
    override = "initial.velocity=[0, 0, -2]"
    assert main(["run", str(scene_file), "--out", str(out), "--quiet", "--set", override]) == 0
    if MPI.COMM_WORLD.rank:
        return
    log = (out / "run.log").read_text()
    summary = json.loads((out / "summary.json").read_text())
    commit = checkout_commit()
    assert summary["version"] == rwall_fem.__version__
    if commit is None:
        assert summary["git_hash"] is None
    else:
        assert summary["git_hash"].removesuffix("+dirty") == commit
        assert log.startswith(f"rwall-fem {rwall_fem.__version__} (git {commit}")
    assert f"{MPI.COMM_WORLD.size} MPI rank(s)" in log
    assert f"dolfinx {dolfinx.__version__}" in log and ", mpi " in log and "petsc " in log
    # The scene as it ran, defaults and override applied: TOML that reads back into it.
    echo = log.split("(defaults and overrides applied):\n")[1].split("\n\n")[0]
    echoed = tomllib.loads("\n".join(line.removeprefix("    ") for line in echo.splitlines()))
    ran = load_scene(scene_file, [override])
    assert parse_scene(echoed, source=ran.source) == ran
    assert "velocity = [0.0, 0.0, -2.0]" in echo and "dt_scale = 0.9" in echo
    assert "mesh: 40 hexahedron cells, 99 nodes" in log
    assert "wall[0]: plane, slide free, 90 secondary nodes" in log
    cycle = (r"^ +(\d+) +(\S+) +(\S+) +(\S+) +(\S+) +(\d+) +(\S+) +(\S+)"
             r"  at \((\S+), (\S+), (\S+)\) m$")  # fmt: skip
    cycles = re.findall(cycle, log, re.MULTILINE)
    steps = summary["steps"]
    assert [int(c[0]) for c in cycles] == [*range(0, steps, 10), steps]
    assert all(float(c[2]) == pytest.approx(summary["dt"], rel=1e-4) for c in cycles)
    # The projection: an elastic body's step does not change, so the steps left at each
    # line are those the run then took.
    assert [int(c[5]) for c in cycles] == [steps - int(c[0]) for c in cycles]
    assert cycles[0][6] == "-" and float(cycles[-1][6]) == 0.0
    # The cell that controls the step: its stable step (dt = dt_scale x it, rounded down to
    # 4 figures) and where it is, inside the bar.
    low, high = summary["deformed_bounds"]
    for c in cycles:
        assert 0.9 * float(c[7]) == pytest.approx(float(c[2]), rel=1e-3)
        where = [float(x) for x in c[8:]]
        assert all(lo - 1e-3 <= x <= hi + 1e-3 for lo, x, hi in zip(low, where, high, strict=True))
    assert "ended: done" in log and f"steps: {steps} of {steps} planned" in log
    assert f"max energy balance error: {summary['energy']['max_balance_error']:.3e}" in log
    assert log.rstrip().endswith("s after the time loop")


@pytest.mark.serial
def test_batch_runs_print_cycle_lines_and_no_compiler_chatter(tmp_path):
    """stderr of a run that is not a terminal gets the cycle lines (none with --quiet);
    forms compiled afresh (an empty FFCx cache) log nothing to it."""
    (tmp_path / "scene.toml").write_text(SCENE.replace("frames = 3", "frames = 0\nplot = false"))
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    kernels = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    env |= {"XDG_CACHE_HOME": str(tmp_path / "cache"),
            "RWALL_FEM_CACHE": str(Path(kernels) / "rwall_fem" / "kernels")}  # fmt: skip
    command = [sys.executable, "-m", "rwall_fem", "run", "scene.toml", "--out", "out"]
    loud = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True)
    quiet = subprocess.run([*command, "--quiet"], cwd=tmp_path, env=env, capture_output=True,
                           text=True)  # fmt: skip
    assert loud.returncode == quiet.returncode == 0, loud.stderr + quiet.stderr
    lines = loud.stderr.splitlines()
    assert lines[0].split() == ["rwall-fem:", "cycle", "time", "(s)", "dt", "(s)", "energy",
                                "error", "%", "elapsed", "(s)", "steps", "left", "left", "(s)",
                                "limit", "(s)", "controlling", "cell"]  # fmt: skip
    assert len(lines) > 10 and all(re.match(r"rwall-fem: +\d+ ", line) for line in lines[1:])
    assert quiet.stderr == ""
