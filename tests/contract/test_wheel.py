"""The package works once installed: a wheel built from the repository holds every module
and the geometry of the built-in shapes, and runs a shape scene from another folder.

The wheel is built offline from a copy of the sources (so the build leaves nothing in
the repository) with the leg's own setuptools, installed without dependencies into a
fresh venv, and run there from a temporary folder. The fresh venv sees the leg's
packages (DOLFINx, gmsh, numpy, ...) through a ``.pth`` file naming the test
interpreter's site directories, as ``--system-site-packages`` would for a system-wide
DOLFINx, and the shared libraries that wheels such as mpich and gmsh put into the
environment's ``lib/`` (where mpi4py and gmsh look for them) through links;
rwall_fem itself comes only from the wheel.
"""

import json
import os
import shutil
import site
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.serial

SCENE = """
[run]
end_time = 1e-5
[mesh]
shape = "round_bar"
radius = 0.003
length = 0.01
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
frames = 0
plot = false
"""


def _run(*args, **kwargs):
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    env |= {"PIP_NO_INDEX": "1", "PIP_DISABLE_PIP_VERSION_CHECK": "1", "PYTHONNOUSERSITE": "1"}
    result = subprocess.run(
        [str(a) for a in args], env=env, capture_output=True, text=True, timeout=600, **kwargs
    )
    assert result.returncode == 0, f"{args}:\n{result.stdout[-2000:]}\n{result.stderr[-3000:]}"
    return result


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel built from a copy of the repository's package sources."""
    pytest.importorskip("setuptools", reason="building the wheel needs setuptools")
    tmp = tmp_path_factory.mktemp("wheel")
    source = tmp / "source"
    source.mkdir()
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for name in ("rwall_fem", "meshes"):
        shutil.copytree(REPOSITORY / name, source / name, ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPOSITORY / name, source / name)
    _run(sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "--wheel-dir", tmp / "dist", source)  # fmt: skip
    (built,) = (tmp / "dist").glob("rwall_fem-*.whl")
    return built


def test_the_wheel_holds_every_module_the_geometry_the_kernels_and_the_schema(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    package = REPOSITORY / "rwall_fem"
    files = {
        p.relative_to(REPOSITORY).as_posix()
        for pattern in ("**/*.py", "kernels/*.c", "kernels/*.h", "scene/*.json")
        for p in package.glob(pattern)
    }
    geometry = {f"rwall_fem/meshes/{p.name}" for p in (REPOSITORY / "meshes").glob("*.geo")}
    assert len(geometry) >= 5 and "rwall_fem/scene/scene.schema.json" in files
    assert files | geometry <= names, sorted((files | geometry) - names)


def test_an_installed_wheel_runs_a_built_in_shape_from_another_folder(wheel, tmp_path):
    venv = tmp_path / "venv"
    _run(sys.executable, "-m", "venv", "--system-site-packages", "--without-pip", venv)
    python = venv / "bin" / "python"
    ours = _run(python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))")
    ours = Path(ours.stdout.strip())
    leg = [p for p in [*site.getsitepackages(), site.getusersitepackages()] if Path(p).is_dir()]
    (ours / "leg.pth").write_text("".join(f"{p}\n" for p in leg))
    for library in (Path(sys.prefix) / "lib").iterdir():
        if not library.name.startswith("python"):
            (venv / "lib" / library.name).symlink_to(library)
    _run(sys.executable, "-m", "pip", "--python", python, "install", "--no-deps", wheel)

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    where = _run(python, "-c", "import rwall_fem.meshing as m; print(m.__file__)", cwd=elsewhere)
    assert Path(where.stdout.strip()).is_relative_to(venv)
    (elsewhere / "scene.toml").write_text(SCENE)
    _run(venv / "bin" / "rwall-fem", "run", "scene.toml", "--out", "out", "--quiet",
         cwd=elsewhere)  # fmt: skip
    summary = json.loads((elsewhere / "out" / "summary.json").read_text())
    assert summary["status"] == "done" and summary["cells"] > 0
