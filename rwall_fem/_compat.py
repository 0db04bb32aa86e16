"""The one place where DOLFINx 0.5 and DOLFINx 0.10+ differ.

Everything else in rwall_fem is written in the current DOLFINx idiom and
calls these helpers where a name or a signature changed. Importing this
module also puts ``dolfinx_solver`` (the PyPI wheel that bundles PETSc and
MPICH) before ``dolfinx`` and ``petsc4py`` when it is installed, as that
wheel requires.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import importlib.util
import inspect
import logging
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

# PETSc puts its own handlers on SIGTERM, SIGBUS, SIGSEGV, ... when it starts (the PyPI
# wheel's does), in place of Python's: SIGTERM would end the process through MPI_Abort
# without a word, before rwall_fem.interrupts could say why (exit 143 or 15).
if "-no_signal_handler" not in os.environ.get("PETSC_OPTIONS", ""):
    os.environ["PETSC_OPTIONS"] = f"{os.environ.get('PETSC_OPTIONS', '')} -no_signal_handler"

# SCOTCH 7 (Debian's, under DOLFINx 0.5) partitions with threads, and its threads make
# the partition of a mesh differ from run to run (seen on 2 ranks: the halves swapped, in
# one run out of three, whatever the mesh): a checkpoint is then another partition's, and
# a resumed run refuses it. One thread gives the same partition every time.
os.environ.setdefault("SCOTCH_PTHREAD_NUMBER", "1")

if importlib.util.find_spec("dolfinx_solver") is not None:
    import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

import dolfinx
import dolfinx.fem.petsc  # noqa: F401  (registers fem.petsc)
import dolfinx.jit
import numpy as np
from dolfinx import fem, plot

__all__ = [
    "DOLFINX_VERSION",
    "assemble_matrix",
    "cell_nodes",
    "compiled",
    "create_vector",
    "expression",
    "form",
    "scalar_space",
    "scatter_reverse_add",
    "model_to_mesh",
    "vector_space",
    "vtk_mesh",
]

DOLFINX_VERSION = dolfinx.__version__
_MODERN = hasattr(fem, "functionspace")


def vector_space(msh) -> fem.FunctionSpace:
    """Continuous piecewise-linear (P1/Q1) vector space of dimension gdim on ``msh``."""
    gdim = msh.geometry.dim
    if _MODERN:
        return fem.functionspace(msh, ("Lagrange", 1, (gdim,)))
    return compiled(lambda: fem.VectorFunctionSpace(msh, ("Lagrange", 1)))  # FFCx's element


def vtk_mesh(V):
    """``(topology, cell_types, points)`` of the local cells of ``V``, for pyvista."""
    if _MODERN:
        return plot.vtk_mesh(V)
    return plot.create_vtk_mesh(V)


def cell_nodes(V) -> np.ndarray:
    """Node (block) indices of each local cell of ``V``: shape (num_cells, nodes_per_cell)."""
    dofs = V.dofmap.list
    if isinstance(dofs, np.ndarray):
        return dofs
    return dofs.array.reshape(-1, V.dofmap.dof_layout.num_dofs)


def model_to_mesh(model, comm, rank: int, gdim: int = 3):
    """Distribute a gmsh model built on ``rank``: ``(msh, cell_tags, facet_tags)``."""
    if _MODERN:
        from dolfinx.io import gmsh as gmshio

        data = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
        return data.mesh, data.cell_tags, data.facet_tags
    from dolfinx.io import gmshio

    return gmshio.model_to_mesh(model, comm, rank, gdim=gdim)


def assemble_matrix(form, mat_type: str):
    """Assemble the bilinear ``form`` into a new, assembled PETSc matrix of type ``mat_type``.

    ``mat_type`` is a PETSc type such as ``"baij"``; DOLFINx preallocates it from the
    form's sparsity pattern (converting an assembled AIJ matrix instead takes minutes
    at a million cells).
    """
    if "kind" in inspect.signature(fem.petsc.assemble_matrix).parameters:
        A = fem.petsc.assemble_matrix(form, kind=mat_type)
    else:
        A = fem.petsc.create_matrix(form, mat_type)
        fem.petsc.assemble_matrix(A, form)
    A.assemble()
    return A


def create_vector(V, form):
    """A ghosted PETSc vector for assembling the linear ``form`` whose test space is ``V``."""
    first = next(iter(inspect.signature(fem.petsc.create_vector).parameters))
    return fem.petsc.create_vector(V if first == "V" else form)


def scalar_space(msh, family: str = "DG", degree: int = 0) -> fem.FunctionSpace:
    """Scalar space, e.g. piecewise constants for cell data."""
    if _MODERN:
        return fem.functionspace(msh, (family, degree))
    return compiled(lambda: fem.FunctionSpace(msh, (family, degree)))  # FFCx's element


def form(ufl_form) -> fem.Form:
    """``ufl_form`` compiled (FFCx, cached: :func:`compiled`)."""
    return compiled(lambda: fem.form(ufl_form))


def expression(expr, V) -> fem.Expression:
    """``expr`` compiled for interpolation into ``V`` (FFCx, cached: :func:`compiled`)."""
    points = V.element.interpolation_points
    return compiled(lambda: fem.Expression(expr, points() if callable(points) else points))


def compiled(build):
    """``build()``, a call that compiles forms with FFCx and the C compiler, made robust:

    - its cache (``~/.cache/fenics``, or under ``$XDG_CACHE_HOME``) must be writable, else
      a private temporary folder takes its place for this process, with a warning;
    - a compiler that fails or is missing is one line (:func:`~rwall_fem.kernels.compiler_error`),
      on every rank, as for the element kernels;
    - a stop signal during the compilation leaves the cache as a failed compilation does:
      FFCx would otherwise wait for the lost module at its next use, then fail;
    - a failed compilation is tried once more, on every rank alike (DOLFINx's MPI wrapper
      tells the ranks other than 0 only that it failed): a module that another process
      left unfinished (killed while it compiled), which FFCx names once it has waited for
      it in vain, is set aside first.
    """
    from rwall_fem.kernels import compiler_error

    cache = _form_cache()
    for attempt in (1, 2):
        started = time.time()
        try:
            return build()
        except KeyboardInterrupt:
            _drop_unfinished(cache, started)
            raise
        except Exception as err:
            if not _compiler_failed(err):
                raise
            if attempt == 1:
                _set_aside_timed_out(" ".join(str(err).split()))
                continue
            detail = (str(err).strip().splitlines() or [type(err).__name__])[-1]
            raise compiler_error("DOLFINx's forms (FFCx)", detail) from None


@functools.cache
def _form_cache() -> Path:
    """DOLFINx's form cache folder, or a private temporary one when it cannot be written."""
    defaults = getattr(dolfinx.jit, "DOLFINX_DEFAULT_JIT_OPTIONS", None)
    if defaults is None:  # DOLFINx 0.5
        defaults = dolfinx.jit.DOLFINX_DEFAULT_JIT_PARAMETERS
    folder, doc = defaults["cache_dir"]
    folder = Path(str(folder)).expanduser()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        os.rmdir(tempfile.mkdtemp(prefix=".rwall-fem-probe-", dir=folder))
    except OSError as err:
        logging.getLogger("rwall_fem").warning(
            "the form cache %s cannot be written (%s): DOLFINx's forms are compiled for this "
            "process only (set XDG_CACHE_HOME to a folder it can write)",
            folder,
            err.strerror,
        )
        folder = Path(tempfile.mkdtemp(prefix="rwall_fem_forms_"))
        atexit.register(shutil.rmtree, folder, True)
        defaults["cache_dir"] = (folder, doc)
    return folder


# Exceptions of a C compilation, by name: setuptools moves its classes between versions.
_COMPILER_ERRORS = {"VerificationError", "CompileError", "LinkError", "CCompilerError",
                    "DistutilsExecError", "DistutilsPlatformError"}  # fmt: skip


def _compiler_failed(err: BaseException) -> bool:
    """Whether ``err`` (or what it was raised from) is a failed C compilation; DOLFINx's
    MPI wrapper turns it into a RuntimeError on every rank."""
    while err is not None:
        if _COMPILER_ERRORS & {t.__name__ for t in type(err).__mro__}:
            return True
        if isinstance(err, RuntimeError) and "compilation" in str(err).lower():
            return True
        err = err.__cause__ or err.__context__
    return False


def _set_aside_timed_out(message: str) -> None:
    """Rename as failed the unfinished C file that FFCx names when ``message`` says that
    it waited for it in vain."""
    named = re.search(r"timed out.*remove (\S+\.c)\)", message)
    if named:
        with contextlib.suppress(OSError):
            Path(named[1]).replace(Path(named[1] + ".failed"))


def _drop_unfinished(cache: Path, since: float) -> None:
    """Mark the C files of this compilation (FFCx's claim on a module, made since
    ``since``, without the ``.c.cached`` file of a finished one) as failed, as FFCx does
    when a compilation raises an Exception: the next use compiles again."""
    for source in cache.glob("*.c"):
        try:
            if source.stat().st_mtime >= since - 1 and not source.with_suffix(".c.cached").exists():
                source.replace(source.with_suffix(".c.failed"))
        except OSError:
            continue


def scatter_reverse_add(x) -> None:
    """Add the ghost entries of the DOLFINx vector ``x`` to their owners' entries."""
    from dolfinx import la

    x.scatter_reverse(la.InsertMode.add if hasattr(la, "InsertMode") else la.ScatterMode.add)
