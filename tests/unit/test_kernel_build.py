"""The first use of the kernels compiles them (``rwall_fem.kernels``): what the compiler
says stays out of the run's output, which carries the run's own lines only (a user's first
run printed some 120 lines of GCC's warnings before the one line of a refused scene).

A stand-in compiler, a script that writes a warning on its standard error and then runs
the real one, builds a small extension (the material point's plastic update): nothing it
wrote reaches the process's output, and the module works. The same script failing makes
a message that ends with its first error, in one line.
"""

import os
import shutil
import stat

import pytest
from mpi4py import MPI

from rwall_fem import kernels
from rwall_fem.kernels import ELEMENT_PARAMS, Extension

POINT = Extension(
    "_rwall_build_test",
    ("batch.h", "materials.h", "plasticity.h", "failure.h", "material_point.c"),
    ELEMENT_PARAMS + "\ndouble plastic_point(const element_params *p, double sigma[6],"
    " double *eps_p, double *T, const double dL[9]);\n",
    "the material point",
)

pytestmark = [
    pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="compiles on one process"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc"),
]


def compiler(folder, says: str, then: str):
    """A compiler script in ``folder`` that writes ``says`` on its standard error, then
    runs ``then`` (a shell command line, "$@" its arguments)."""
    path = folder / "talking-cc"
    path.write_text(f'#!/bin/sh\necho "{says}" >&2\n{then}\n')
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(path)


def test_the_compilers_warnings_stay_out_of_the_output(tmp_path, capfd, monkeypatch):
    monkeypatch.setenv("CC", compiler(tmp_path, "talking-cc: warning: a word", 'exec gcc "$@"'))
    path, _ = kernels._build(POINT, "_rwall_build_test_quiet", kernels.FLAG_SETS[-1],
                             tmp_path / "cache")  # fmt: skip
    out, err = capfd.readouterr()
    assert "talking-cc" not in out + err, out + err
    lib = kernels._import("_rwall_build_test_quiet", path).lib
    assert lib.plastic_point is not None
    assert os.path.isfile(path)


def test_a_failing_compilers_first_error_ends_the_message(tmp_path, capfd, monkeypatch):
    monkeypatch.setenv("CC", compiler(tmp_path, "talking-cc: error: no, not today", "exit 1"))
    with pytest.raises(RuntimeError) as failure:
        kernels._build(POINT, "_rwall_build_test_fails", kernels.FLAG_SETS[-1],
                       tmp_path / "cache")  # fmt: skip
    out, err = capfd.readouterr()
    assert "talking-cc" not in out + err, out + err
    (line,) = str(failure.value).splitlines()
    assert line.endswith("talking-cc: error: no, not today")
