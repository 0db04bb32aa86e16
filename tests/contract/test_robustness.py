"""Nothing silent, nothing half-written (issue 20): one test per class of hostile case.

1. stop signals outside the time loop (meshing, compiling, drawing the pictures, the
   ``render`` command), serially and on 2 ranks where MPI changes the path;
2. the compile caches (a cut library, a cache that cannot be written, no compiler);
3. non-finite results (strict JSON, no warnings, the balance error before the NaN);
4. a full disk (a small tmpfs: root only);
5. checkpoints whose container is valid but whose contents are not;
6. ``render`` on a folder with a cut frame file;
7. ``rwall-fem study`` inside the command line's error handling;
8. hourglass keys on a mesh file of tetrahedra: ``bad_scenes/100_*`` to ``102_*``;
10. argparse's errors in one line, ``--resume`` into a folder that does not exist, a
    tiny ``output.checkpoint_seconds`` (``bad_scenes/103_*``).

A signal test starts the command (on 1 or 2 ranks of this leg's MPI), waits until it is
in the stage named, sends the signal to the process the user would signal (the launcher
under MPI) and checks: one ``rwall-fem:`` line, exit code 3 (Open MPI's ``mpirun`` exits
1 after a signal whatever its ranks return), no child process left, and the results
folder as the docs say.
"""

import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import SCENE, mpi_launch
from mpi4py import MPI

from rwall_fem import _compat, kernels
from rwall_fem.cli import main

BAD = Path(__file__).resolve().parents[1] / "bad_scenes"
# A body whose meshing takes seconds (gmsh's 3-D mesher on a fine round bar).
SLOW_MESH = """
[run]
end_time = 2e-6
[mesh]
shape = "round_bar"
radius = 0.01
length = 0.1
element_size = 0.0007
cell = "tetrahedron"
[material]
model = "linear_elastic"
density = 7850.0
young = 210e9
poisson = 0.3
[output]
frames = 0
"""


def _env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    return env | extra


def _start(args, cwd, ranks=1, env=None):
    launch, mpi_env = mpi_launch(ranks) if ranks > 1 else ([], _env())
    return subprocess.Popen(
        [*launch, sys.executable, "-m", "rwall_fem", *args],
        cwd=cwd,
        env=mpi_env | (env or {}),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _descendants(pid: int) -> set[int]:
    """Living processes below ``pid`` (from /proc)."""
    table = {}
    for entry in filter(str.isdigit, os.listdir("/proc")):
        try:
            text = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        fields = text[text.rindex(")") + 2 :].split()
        table[int(entry)] = (fields[0], int(fields[1]))
    found, frontier = set(), [pid]
    while frontier:
        parent = frontier.pop()
        for child, (state, ppid) in table.items():
            if ppid == parent and child not in found:
                frontier.append(child)
                if state != "Z":
                    found.add(child)
    return found


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _wait_for(condition, process, seconds=120.0):
    deadline = time.monotonic() + seconds
    while not condition():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.05)


def _stopped(process, sig, ranks=1) -> list[str]:
    """Send ``sig``; the ``rwall-fem:`` lines of the ended command (one), its code checked."""
    started = _descendants(process.pid)
    process.send_signal(sig)
    _, stderr = process.communicate(timeout=60)
    ours = [line for line in stderr.splitlines() if line.startswith("rwall-fem:")]
    reason = "interrupted (SIGINT, Ctrl-C)" if sig == signal.SIGINT else "terminated by SIGTERM"
    assert len(ours) == 1 and ours[0].startswith(f"rwall-fem: stopped: {reason}"), stderr
    assert "Traceback" not in stderr
    openmpi = ranks > 1 and not mpi_launch(ranks)[0][0].endswith("mpiexec")
    assert process.returncode == (1 if openmpi else 3), stderr
    # The launcher's daemon and the ranks it kills end within a moment of the command, a
    # moment that a loaded machine stretches: each must be gone within seconds.
    deadline = time.monotonic() + 10.0
    while (left := {pid for pid in started if _alive(pid)}) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not left, f"left running: {left}"
    return ours


def _loaded(process, library: str) -> bool:
    """Whether a process of the command has mapped ``library`` (gmsh: it is meshing)."""
    for pid in _descendants(process.pid) | {process.pid}:
        try:
            if library in Path(f"/proc/{pid}/maps").read_text():
                return True
        except OSError:
            continue
    return False


# --- 1. stop signals outside the time loop --------------------------------------------


@pytest.mark.serial
@pytest.mark.parametrize("ranks, sig", [(1, signal.SIGINT), (2, signal.SIGTERM)])
def test_a_stop_signal_while_meshing_is_one_line(tmp_path, ranks, sig):
    """gmsh sets Ctrl-C to end the process silently, PETSc puts its own handler on
    SIGTERM: the command's handlers stay, and a signal while gmsh's C code runs ends every
    rank at once, with one line, before anything was written."""
    (tmp_path / "scene.toml").write_text(SLOW_MESH)
    process = _start(["run", "scene.toml", "--out", "out", "--lift-limits"], tmp_path, ranks)
    _wait_for(lambda: _loaded(process, "libgmsh"), process)
    time.sleep(1.0)  # into gmsh's 3-D mesher, a few seconds long
    _stopped(process, sig, ranks)
    assert not (tmp_path / "out").exists()


@pytest.mark.serial
def test_a_stop_signal_while_compiling_stops_the_compiler(tmp_path):
    """SIGTERM while the C compiler builds the kernels into an empty cache: the compiler
    and what it runs stop with the command, and the cache holds no temporary folder."""
    (tmp_path / "scene.toml").write_text(SCENE)
    cache = tmp_path / "kernels"
    process = _start(["check", "scene.toml"], tmp_path, env={"RWALL_FEM_CACHE": str(cache)})
    _wait_for(lambda: cache.exists() and any(cache.iterdir()), process)
    time.sleep(0.5)
    _stopped(process, signal.SIGTERM)
    assert list(cache.iterdir()) == []


@pytest.mark.serial
@pytest.mark.parametrize("ranks", [1, 2])
def test_a_stop_signal_while_drawing_the_pictures(tmp_path, ranks):
    """SIGTERM while rank 0 renders the frames after the last step: the renderer stops
    with the command, the summary says "stopped" and why, the lock is gone; then Ctrl-C in
    ``rwall-fem render`` of the same folder is one line too."""
    # Large pictures, many of them: the reused scene draws a small one in a few ms.
    slow = SCENE.replace("frames = 3", "frames = 200") + "\n[output.view]\nsize = [1600, 1200]\n"
    (tmp_path / "scene.toml").write_text(slow)
    out = tmp_path / "out"
    process = _start(["run", "scene.toml", "--out", "out", "--quiet"], tmp_path, ranks)
    _wait_for(lambda: any((out / "frames").glob("*.png")), process)
    [line] = _stopped(process, signal.SIGTERM, ranks)
    assert "after the last step, while the outputs were being finished" in line
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "stopped" and summary["steps"] == summary["planned_steps"]
    assert "terminated by SIGTERM after the last step" in summary["reason"]
    assert not (out / ".rwall-fem.lock").exists()
    assert "then stopped: terminated by SIGTERM" in (out / "run.log").read_text()
    drawn = len(list((out / "frames").glob("*.png")))
    time.sleep(1.0)
    assert len(list((out / "frames").glob("*.png"))) == drawn < 200  # nothing draws on

    if ranks == 1:
        for png in (out / "frames").glob("*.png"):
            png.unlink()
        process = _start(["render", "out"], tmp_path)
        _wait_for(lambda: any((out / "frames").glob("*.png")), process)
        _stopped(process, signal.SIGINT)


# --- 2. the compile caches --------------------------------------------------------------


def test_a_cached_kernel_library_is_checked_before_it_is_loaded(tmp_path):
    """A library cut short or changed fails its digest and is removed (it would crash
    the process with SIGBUS or fail to import); one of an older version is left alone."""
    name = "_rwall_kernels_0123456789abcdef"
    good = tmp_path / "good.so"
    good.write_bytes(os.urandom(4096))
    digest = kernels._digest(good)
    whole = tmp_path / f"{name}.{digest}.so"
    shutil.copy(good, whole)
    assert kernels._cached(name, tmp_path) == whole
    with open(whole, "r+b") as file:
        file.truncate(1000)
    older = tmp_path / f"{name}.cpython-311-x86_64-linux-gnu.so"
    older.write_bytes(b"another version's")
    assert kernels._cached(name, tmp_path) is None
    assert not whole.exists() and older.exists()


def test_a_cache_that_cannot_be_written_gives_way_to_a_private_one(tmp_path, monkeypatch):
    """The kernels' cache and DOLFINx's form cache: a folder that cannot be written (a
    file in the way here; a read-only file system alike) is replaced by a private
    temporary folder, with a warning."""
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")

    def compile_(extension, name, flags, work):
        library = work / f"{name}.so"
        library.write_bytes(b"built")
        return library

    monkeypatch.setattr(kernels, "_compile", compile_)
    final, private = kernels._build(kernels.ELEMENTS, "_rwall_kernels_x", [], blocked / "kernels")
    assert private is not None and final.parent == private and final.read_bytes() == b"built"
    shutil.rmtree(private)

    defaults = dict(DEFAULTS)
    defaults["cache_dir"] = (blocked / "fenics", "doc")
    monkeypatch.setattr(_jit(), _DEFAULTS_NAME, defaults)
    _compat._form_cache.cache_clear()
    try:
        folder = _compat._form_cache()
        assert folder.is_dir() and folder != blocked / "fenics"
        assert defaults["cache_dir"][0] == folder
    finally:
        _compat._form_cache.cache_clear()



@pytest.mark.serial
def test_processes_starting_together_share_one_kernel_cache(tmp_path):
    """Two processes (ranks starting together) load an extension into an empty cache at
    once, through the one loader of :mod:`rwall_fem.kernels` (the solids' and the shells'
    kernels take it; a small extension here, quick to compile): both load, the cache then
    holds whole libraries of one key only (no build folder left), and a later process
    loads what is there without publishing anything new."""
    code = ("from rwall_fem import kernels; kernels.load(kernels.Extension('_rwall_probe', "
            "('batch.h',), '', 'a probe'))")  # fmt: skip
    env = _env(RWALL_FEM_CACHE=str(tmp_path))
    both = [subprocess.Popen([sys.executable, "-c", code], env=env, stderr=subprocess.PIPE,
                             text=True) for _ in range(2)]  # fmt: skip
    for process in both:
        _, err = process.communicate(timeout=600)
        assert process.returncode == 0, err
    libraries = {path: path.stat().st_mtime_ns for path in tmp_path.iterdir()}
    assert libraries and all(p.suffix == ".so" for p in libraries), sorted(libraries)
    assert len({p.name.split(".")[0] for p in libraries}) == 1  # one key: one source set
    later = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                           text=True, timeout=600)  # fmt: skip
    assert later.returncode == 0, later.stderr
    assert {path: path.stat().st_mtime_ns for path in tmp_path.iterdir()} == libraries

def _jit():
    import dolfinx.jit

    return dolfinx.jit


_DEFAULTS_NAME = next(
    name
    for name in ("DOLFINX_DEFAULT_JIT_OPTIONS", "DOLFINX_DEFAULT_JIT_PARAMETERS")
    if hasattr(_jit(), name)
)
DEFAULTS = getattr(_jit(), _DEFAULTS_NAME)


@pytest.mark.serial
def test_no_c_compiler_is_one_line(tmp_path):
    """No C compiler and empty caches: the form compiler meets it first (DOLFINx compiles
    a form before the kernels are needed); one line, exit 2, as for the kernels."""
    (tmp_path / "scene.toml").write_text(SCENE)
    env = {"CC": "/nonexistent/cc", "RWALL_FEM_CACHE": str(tmp_path / "kernels"),
           "XDG_CACHE_HOME": str(tmp_path / "cache")}  # fmt: skip
    result = subprocess.run(
        [sys.executable, "-m", "rwall_fem", "check", "scene.toml"],
        cwd=tmp_path,
        env=_env(**env),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "could not compile" in lines[0], result.stderr
    assert "/nonexistent/cc" in lines[0] and "install gcc" in lines[0]


# --- 3. non-finite results --------------------------------------------------------------


def test_a_run_that_turns_nan_leaves_strict_json_and_no_warnings(shared_dir, capsys):
    """A gravity of 1e300 m/s^2 blows the run up: it stops in one line, without numpy's
    warnings; summary.json is strict JSON (null where a value is NaN or Inf, and the keys
    listed), with the balance error up to the last finite step."""
    comm, out = MPI.COMM_WORLD, Path(shared_dir)
    if comm.rank == 0:
        (out / "scene.toml").write_text(SCENE)
    comm.Barrier()
    args = ["run", str(out / "scene.toml"), "--out", str(out / "run"), "--quiet"]
    args += ["--set", "output.frames=0", "--set", "gravity.acceleration=[0, 0, -1e300]"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(args) == 3
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)]
    if comm.rank == 0:
        [line] = capsys.readouterr().err.strip().splitlines()
        assert "NaN or Inf in the nodal state" in line

        def refuse(constant):
            raise ValueError(f"{constant} is not JSON")

        text = (out / "run" / "summary.json").read_text()
        summary = json.loads(text, parse_constant=refuse)
        assert summary["status"] == "stopped" and summary["non_finite"]
        for key in summary["non_finite"]:
            assert key.startswith(("energy.", "walls[", "final_momentum", "deformed_bounds"))
        assert math.isfinite(summary["energy"]["max_balance_error"])  # not NaN, not 0 by it
        assert summary["energy"]["max_balance_error"] < 1e-6


# --- 4. a full disk ---------------------------------------------------------------------


@pytest.fixture
def full_disk(shared_dir):
    """A 64 kB tmpfs (rank 0 mounts it for every rank of this host); skipped unless root."""
    comm, where = MPI.COMM_WORLD, Path(shared_dir) / "disk"
    mounted = None
    if comm.rank == 0:
        where.mkdir()
        mount = ["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(where)]
        mounted = os.geteuid() == 0 and subprocess.run(mount, capture_output=True).returncode == 0
    if not comm.bcast(mounted, root=0):
        pytest.skip("mounting a small tmpfs needs root")
    yield where
    comm.Barrier()
    if comm.rank == 0:
        subprocess.run(["umount", str(where)], check=True)


def test_a_full_disk_names_the_file_and_leaves_whole_rows(full_disk, capsys):
    """The results folder fills up while the run goes: every rank ends (exit 4) at the
    same step, with one line naming the table that could not be written (energy.csv or
    walls.csv: they are flushed together, and which one meets the full disk first depends
    on how many rows a flush holds), and both tables end with a whole row."""
    comm, out = MPI.COMM_WORLD, full_disk / "run"
    scene = full_disk.parent / "long.toml"
    if comm.rank == 0:
        scene.write_text(SCENE.replace("end_time = 2e-5", "end_time = 1.0"))
    comm.Barrier()
    args = ["run", str(scene), "--out", str(out), "--quiet", "--lift-limits"]
    assert main([*args, "--set", "output.frames=0", "--set", "output.plot=false"]) == 4
    if comm.rank == 0:
        [line] = capsys.readouterr().err.strip().splitlines()
        full = next(name for name in ("energy.csv", "walls.csv") if str(out / name) in line)
        assert line.startswith(f"rwall-fem: error: outputs: {out / full}: ")
        assert "No space left on device" in line
        for name in ("energy.csv", "walls.csv"):  # the other may hold nothing yet
            text = (out / name).read_text()
            assert text.endswith("\n") or not text, name
            assert len({row.count(",") for row in text.splitlines()}) <= 1, name
        assert (out / full).read_text()  # its header at least
        summary = json.loads((out / "summary.json").read_text())  # its room was kept
        assert summary["status"] == "failed" and full in summary["reason"]
        assert not (out / ".rwall-fem.lock").exists()


# --- 5. checkpoints whose contents are wrong --------------------------------------------


@pytest.mark.parametrize(
    "spoil, message",
    [
        (lambda a: a | {"header": np.array("null")}, "its header is NoneType, not a checkpoint"),
        (lambda a: a | {"header": np.array("{}")}, "its header has no code (a str)"),
        (lambda a: a | {"state/u": np.zeros(3)}, "state/u has the shape (3,); this run's is"),
        (lambda a: a | {"state/v": np.array(["a"] * 3)}, "state/v has the shape"),
        (lambda a: {k: v for k, v in a.items() if k != "state/clock"}, "state has no 'clock'"),
    ],
    ids=["null-header", "empty-header", "u-of-3", "v-of-text", "no-clock"],
)
def test_a_checkpoint_with_wrong_contents_is_one_line(spoil, message, shared_dir, capsys):
    comm, out = MPI.COMM_WORLD, Path(shared_dir)
    if comm.rank == 0:
        (out / "scene.toml").write_text(SCENE)
    comm.Barrier()
    args = ["run", str(out / "scene.toml"), "--out", str(out / "run"), "--quiet"]
    args += ["--set", "output.frames=0", "--set", "output.plot=false"]
    assert main([*args, "--set", "output.checkpoint_steps=20"]) == 0
    [step] = (out / "run" / "checkpoint").glob("step_*")
    mine = step / "rank_0.npz"
    if comm.rank == 0:
        with np.load(mine) as npz:
            arrays = spoil(dict(npz))
        with open(mine, "wb") as file:
            np.savez(file, **arrays)
    comm.Barrier()
    capsys.readouterr()
    assert main([*args, "--resume"]) == 2
    if comm.rank == 0:
        [line] = capsys.readouterr().err.strip().splitlines()
        assert line.startswith(f"rwall-fem: error: {mine}: ") and message in line, line


# --- 6. render on a folder with a cut frame file ------------------------------------------


@pytest.mark.serial
def test_render_leaves_out_a_cut_frame_file(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    cli = [sys.executable, "-m", "rwall_fem"]
    done = subprocess.run([*cli, "run", "scene.toml", "--out", "out", "--quiet"], cwd=tmp_path,
                          env=_env(), capture_output=True, timeout=300)  # fmt: skip
    assert done.returncode == 0
    data = tmp_path / "out" / "frames" / "data"
    with open(data / "frame_0001.npz", "r+b") as file:
        file.truncate(300)  # what a kill or a full disk leaves
    for png in (tmp_path / "out" / "frames").glob("*.png"):
        png.unlink()
    result = subprocess.run([*cli, "render", "out"], cwd=tmp_path, env=_env(),
                            capture_output=True, text=True, timeout=300)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stderr.splitlines() == [
        "rwall-fem: warning: out/frames/data/frame_0001.npz: cannot be read, left out: not a "
        "whole .npz file (300 bytes, cut short?)"
    ]
    assert sorted(p.name for p in (tmp_path / "out" / "frames").glob("*.png")) == [
        "frame_0000.png", "frame_0002.png"
    ]  # fmt: skip
    with open(data / "mesh.npz", "r+b") as file:
        file.truncate(100)
    result = subprocess.run([*cli, "render", "out"], cwd=tmp_path, env=_env(),
                            capture_output=True, text=True, timeout=300)  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "rwall-fem: error: out/frames/data/mesh.npz: cannot be read: not a whole .npz file "
        "(100 bytes, cut short?)"
    ]


# --- 7. the study command -----------------------------------------------------------------


def test_study_into_a_folder_that_cannot_be_made_is_one_line(shared_dir, capsys):
    comm, blocked = MPI.COMM_WORLD, Path(shared_dir) / "file"
    if comm.rank == 0:
        blocked.write_text("a file where the study's folder would go")
    comm.Barrier()
    assert main(["study", "--quick", "--out", str(blocked / "study")]) == 2
    if comm.rank == 0:
        [line] = capsys.readouterr().err.strip().splitlines()
        assert line.startswith(f"rwall-fem: error: --out: {blocked} is not a folder")


# --- 10. smaller ones ---------------------------------------------------------------------


@pytest.mark.serial
def test_command_line_mistakes_are_one_line(tmp_path):
    cli = [sys.executable, "-m", "rwall_fem"]
    for args, message in [
        (["simulate"], "argument command: invalid choice: 'simulate'"),
        (["run"], "run: the following arguments are required: scene"),
        (["check", "a.toml", "--bogus"], "unrecognized arguments: --bogus"),
    ]:
        result = subprocess.run([*cli, *args], cwd=tmp_path, env=_env(), capture_output=True,
                                text=True, timeout=120)  # fmt: skip
        assert result.returncode == 2
        [line] = result.stderr.splitlines()
        assert line.startswith("rwall-fem: error: ") and message in line, line


def test_resume_into_a_folder_that_does_not_exist_makes_nothing(shared_dir, capsys):
    comm, out = MPI.COMM_WORLD, Path(shared_dir)
    if comm.rank == 0:
        (out / "scene.toml").write_text(SCENE)
    comm.Barrier()
    assert main(["run", str(out / "scene.toml"), "--out", str(out / "new"), "--resume"]) == 2
    assert not (out / "new").exists()
    if comm.rank == 0:
        [line] = capsys.readouterr().err.strip().splitlines()
        assert f"{out / 'new' / 'checkpoint'}: no checkpoint to resume from" in line
