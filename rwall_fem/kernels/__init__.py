"""Compiled element kernels: C compiled at first use through cffi and cached.

The C sources beside this file (one per element family, with the formulas in
their header comments) are compiled into one extension module the first time a
process needs them, the way FFCx compiles forms, and cached per user under
``$XDG_CACHE_HOME/rwall_fem/kernels`` (``~/.cache`` by default; the variable
``RWALL_FEM_CACHE`` overrides the folder). The cache key covers the sources, the
compiler flags, the Python and cffi versions and the processor's instruction
sets, so a cached module never runs on a machine it was not built for.

Flags: ``-O3 -march=native`` (the host's vector instructions) when the compiler
accepts them, else portable ``-O3``; ``-fopenmp-simd`` lets the per-cell loops
over a batch of cells become SIMD instructions without an OpenMP runtime.

Each compile happens in a private temporary folder and the finished module is
moved into the cache with one atomic rename, so concurrent processes (MPI ranks
starting together) never load a half-written file.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import io
import os
import platform
import sys
import tempfile
from functools import cache
from pathlib import Path

__all__ = ["HOURGLASS", "MODELS", "POINT_SLOTS", "STEP_SLOTS", "KernelBuildError", "load"]

SOURCES = ("batch.h", "materials.h", "plasticity.h", "step.h", "tetrahedron.c", "hexahedron.c",
           "hexahedron_reduced.c", "material_point.c", "update.c")  # fmt: skip
# Hidden symbols: no other library's function of the same name (glibc has an ``advance``)
# can take the place of a kernel.
FLAG_SETS = (
    ["-O3", "-march=native", "-fopenmp-simd", "-fno-math-errno", "-fvisibility=hidden"],
    ["-O3", "-fopenmp-simd", "-fno-math-errno", "-fvisibility=hidden"],
)
MODELS = ("linear_elastic", "saint_venant_kirchhoff", "neo_hookean")  # the elastic laws
POINT_SLOTS = 8  # state values per integration point of the plastic kernels (plasticity.h)
STEP_SLOTS = 11  # what a kernel notes of the element steps and inverted cells (step.h)
HOURGLASS = ("none", "physical", "stiffness", "viscous")

_CDEF = (
    """
typedef struct {
  double lmbda, mu, density, wave_speed, hourglass_coefficient, dt;
  int hardening;
  double yield_stress, hardening_modulus, hardening_coefficient, hardening_exponent;
  double rate_coefficient, reference_rate;
  int thermal;
  double thermal_exponent, melting_temperature, room_temperature, specific_heat, taylor_quinney;
  int table_size;
  double table_strain[64], table_stress[64];
  int estimate;
  double calibration;
  const double *length0;
  const double *volume0;
  const double *step_factor;
  double step_floor;
  int32_t *below;
  double *below_step;
} element_params;
double plastic_point(const element_params *p, double sigma[6], double *eps_p, double *T,
                     const double dL[9]);
void tet4_plastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                  const double *v, const element_params *p, double *state, int64_t stride,
                  double *f, double *energy, double *step);
void hex8_plastic(int64_t n, const int32_t *cells, const double *X, const double *u,
                  const double *v, const element_params *p, double *state, int64_t stride,
                  double *f, double *energy, double *step);
void tet4_cell_sizes(int64_t n, const int32_t *cells, const double *x, double *volume,
                     double *length);
void hex8_cell_sizes(int64_t n, const int32_t *cells, const double *x, double *volume,
                     double *length);
"""
    + "".join(
        f"void hex8r_plastic_{hourglass}(int64_t n, const int32_t *cells, const double *X,"
        " const double *u, const double *v, const element_params *p, double *state,"
        " int64_t stride, double *f, double *energy, double *step);\n"
        for hourglass in HOURGLASS
    )
    + """
void internal_acceleration(int64_t n, const double *f, const double *inv_mass, double *a);
void central_difference(int64_t n, double dt_v, double dt, const double *mass, const double *a,
                        double *v, double *u, const double *f, double out[9]);
"""
    + "".join(
        f"void {family}_{model}(int64_t n, const int32_t *cells, const double *X, const double *u,"
        " const element_params *p, double *f, double *energy, double *step);\n"
        for family in ("tet4", "hex8")
        for model in MODELS
    )
    + "".join(
        f"void hex8r_{model}_{hourglass}(int64_t n, const int32_t *cells, const double *X,"
        " const double *u, const double *v, const element_params *p, double *f, double *energy,"
        " double *step);\n"
        for model in MODELS
        for hourglass in HOURGLASS
    )
)


class KernelBuildError(RuntimeError):
    """The C compiler could not build the element kernels; the message is one line."""


def _cache_dir() -> Path:
    if "RWALL_FEM_CACHE" in os.environ:
        return Path(os.environ["RWALL_FEM_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "rwall_fem" / "kernels"


def _cpu() -> str:
    """The machine and its instruction-set flags (what -march=native compiles for)."""
    try:
        text = Path("/proc/cpuinfo").read_text()
        flags = next((line for line in text.splitlines() if line.startswith("flags")), "")
    except OSError:
        flags = platform.processor()
    return f"{platform.machine()} {flags}"


def _key(flags: list[str]) -> str:
    import cffi

    digest = hashlib.sha256()
    here = Path(__file__).parent
    for name in SOURCES:
        digest.update((here / name).read_bytes())
    for part in (_CDEF, " ".join(flags), sys.version, cffi.__version__, _cpu()):
        digest.update(part.encode())
    return digest.hexdigest()[:16]


def _import(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _compile(name: str, flags: list[str], folder: Path) -> Path:
    """Compile the kernels as extension module ``name`` into ``folder``; returns its path."""
    import cffi

    ffi = cffi.FFI()
    ffi.cdef(_CDEF)
    here = Path(__file__).parent
    source = "".join(f'#include "{n}"\n' for n in SOURCES if n.endswith(".c"))
    ffi.set_source(name, source, include_dirs=[str(here)], extra_compile_args=flags)
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder) as work:
        # setuptools reports each compiler command on stdout: keep it out of the run's output.
        with contextlib.redirect_stdout(io.StringIO()):
            built = Path(ffi.compile(tmpdir=work, verbose=False))
        final = folder / built.name
        os.replace(built, final)  # atomic: a concurrent process sees all of it or nothing
    return final


@cache
def load():
    """The compiled kernels ``(ffi, lib)``, built on first use (a few seconds) and cached."""
    failures = []
    for flags in FLAG_SETS:
        name = f"_rwall_kernels_{_key(flags)}"
        folder = _cache_dir()
        found = sorted(folder.glob(f"{name}.*.so")) + sorted(folder.glob(f"{name}.so"))
        try:
            path = found[0] if found else _compile(name, flags, folder)
        except PermissionError:  # a read-only cache: compile for this process only
            path = _compile(name, flags, Path(tempfile.mkdtemp(prefix="rwall_fem_kernels_")))
        except Exception as err:  # the compiler's failure, whatever setuptools wraps it in
            lines = str(err).strip().splitlines() or [type(err).__name__]
            failures.append(f"{' '.join(flags[:2])}: {lines[-1]}")
            continue
        module = _import(name, path)
        return module.ffi, module.lib
    raise KernelBuildError(
        "could not compile the element kernels with the C compiler "
        f"{os.environ.get('CC', 'cc')} ({'; '.join(failures)}): install gcc (Debian: "
        "apt-get install gcc libc6-dev) or set CC to a C compiler"
    )
