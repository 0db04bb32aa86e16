"""What ran: the code's version and git commit, and the versions of what it runs on.

The git commit is that of the checkout the package is imported from (``git`` is asked,
nothing else: no network); an installed wheel has none (None). A checkout with
uncommitted changes to tracked files gets ``+dirty``.
"""

from __future__ import annotations

import platform
import subprocess
from pathlib import Path

__all__ = ["git_hash", "library_versions"]


def git_hash() -> str | None:
    """The commit of the repository holding this package (``+dirty`` if modified), or None."""
    root = Path(__file__).resolve().parents[1]
    if not (root / ".git").exists() or not (root / "pyproject.toml").is_file():
        return None

    def git(*args: str) -> str:
        done = subprocess.run(
            ["git", "-C", str(root), *args], capture_output=True, text=True, timeout=10
        )
        return done.stdout.strip() if done.returncode == 0 else ""

    try:
        commit = git("rev-parse", "HEAD")
        dirty = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError):  # no git on the machine
        return None
    return (commit + ("+dirty" if dirty else "")) or None


def library_versions() -> dict[str, str]:
    """Python, DOLFINx, PETSc, SLEPc, MPI, mpi4py, NumPy and gmsh versions."""
    import dolfinx
    import mpi4py
    import numpy
    import slepc4py
    from mpi4py import MPI
    from petsc4py import PETSc

    from rwall_fem.meshing import gmsh_module

    gmsh = gmsh_module()  # as meshing imports it: a first import here would lose Ctrl-C

    def dotted(version) -> str:
        return ".".join(map(str, version[:3]))

    return {
        "python": platform.python_version(),
        "dolfinx": dolfinx.__version__,
        "petsc": dotted(PETSc.Sys.getVersion()),
        # The package's version, which is SLEPc's: importing slepc4py.SLEPc would
        # initialise SLEPc here, on rank 0 alone (the run log's rank), and its
        # finalisation at exit is collective: the other ranks would never join it.
        "slepc": slepc4py.__version__,
        "mpi": " ".join(MPI.Get_library_version().splitlines()[0].split(",")[0].split()),
        "mpi4py": mpi4py.__version__,
        "numpy": numpy.__version__,
        "gmsh": gmsh.__version__,
    }
