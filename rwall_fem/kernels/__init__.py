"""Compiled element kernels: C compiled at first use through cffi and cached.

The C sources beside this file (one per element family, with the formulas in
their header comments; ``update.c``, ``wall.c``, ``boundary.c`` and ``contact.c`` for the
per-node passes of a step, the update, the rigid walls, the velocity boundaries and the
contact interfaces, the walls and interfaces sharing the friction law of ``friction.h``)
are compiled into one extension module the first time a process needs them, the way
FFCx compiles forms (the shells' kernels into a second one, an :class:`Extension` of
:mod:`rwall_fem.shells.elements`, by the same :func:`load`), and cached per user under
``$XDG_CACHE_HOME/rwall_fem/kernels`` (``~/.cache`` by default; the variable
``RWALL_FEM_CACHE`` overrides the folder). The cache key covers the sources, the
compiler flags, the Python and cffi versions and the processor's instruction
sets, so a cached module never runs on a machine it was not built for.

Flags: ``-O3 -march=native`` (the host's vector instructions) when the compiler
accepts them, else portable ``-O3``; ``-fopenmp-simd`` lets the per-cell loops
over a batch of cells become SIMD instructions without an OpenMP runtime.

The kernels read and write NumPy arrays through raw pointers. A pass bound once and
called every step (a ``functools.partial``, a pointer in ``element_params``) is kept next
to the arrays it points into (a pointer from ``ffi.cast`` keeps nothing alive; one from
``ffi.from_buffer`` keeps its array), and those arrays change in place only
(``x[...] = ``; a checkpoint's values too): an array replaced is bound again before the
next call (``tests/verification/test_bound_arrays.py``).

Each compile happens in a private temporary folder and the finished module is
moved into the cache with one atomic rename, so concurrent processes (MPI ranks
starting together) never load a half-written file. Its name carries the digest of
its bytes, checked before it is loaded: a library cut short (a full disk) or changed
is removed and built again, never loaded. A cache folder that cannot be written (a
read-only file system, another user's) gives way to a private temporary folder, and a
warning says that each run compiles.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import logging
import os
import platform
import re
import shutil
import sys
import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

__all__ = [
    "FAILURE",
    "HOURGLASS",
    "MODELS",
    "POINT_SLOTS",
    "STEP_SLOTS",
    "ELEMENTS",
    "ELEMENT_PARAMS",
    "Extension",
    "KernelBuildError",
    "compiler_error",
    "load",
]

log = logging.getLogger("rwall_fem")

SOURCES = ("batch.h", "materials.h", "plasticity.h", "step.h", "failure.h", "tetrahedron.c",
           "hexahedron.c", "hexahedron_reduced.c", "material_point.c", "update.c",
           "friction.h", "wall.c", "contact.c", "contact_remove.c", "boundary.c")  # fmt: skip
# Hidden symbols: no other library's function of the same name (glibc has an ``advance``)
# can take the place of a kernel.
FLAG_SETS = (
    ["-O3", "-march=native", "-fopenmp-simd", "-fno-math-errno", "-fvisibility=hidden"],
    ["-O3", "-fopenmp-simd", "-fno-math-errno", "-fvisibility=hidden"],
)
MODELS = ("linear_elastic", "saint_venant_kirchhoff", "neo_hookean")  # the elastic laws
POINT_SLOTS = 8  # state values per integration point of the plastic kernels (plasticity.h)
STEP_SLOTS = 12  # what a kernel notes of the element steps, inverted and eroded cells (step.h)
FAILURE = {"plastic_strain": 1, "johnson_cook": 2}  # the failure criteria (failure.h)
HOURGLASS = ("none", "physical", "stiffness", "viscous")

# The constants and arrays every element kernel reads (the shells' too).
ELEMENT_PARAMS = """typedef struct {
  double lmbda, mu, density, wave_speed, hourglass_coefficient, dt;
  int hardening;
  double yield_stress, hardening_modulus, hardening_coefficient, hardening_exponent;
  double rate_coefficient, reference_rate;
  int thermal;
  double thermal_exponent, melting_temperature, room_temperature, specific_heat, taylor_quinney;
  int table_size;
  double table_strain[64], table_stress[64];
  double max_flow_stress;
  int estimate;
  double calibration;
  const double *length0;
  const double *volume0;
  const double *step_factor;
  double step_floor;
  int32_t *below;
  double *below_step;
  const double *nodal_mass;
  double *nodal_stiffness;
  int failure;
  double failure_strain;
  double damage_constants[5];
  double damage_reference_rate;
  int damage_slot;
  int erode;
  double erode_step;
  const int32_t *live;
  int32_t *eroded;
  double *cell_work;
  int64_t cell_stride;
  const double *velocity;
} element_params;"""
_CDEF = (
    f"\n{ELEMENT_PARAMS}\n"
    + """double plastic_point(const element_params *p, double sigma[6], double *eps_p, double *T,
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
void shell_acceleration(int64_t n, const double *f, const double *inv_mass, double *a,
                        const double *moments, const double *inv_inertia, const double *free,
                        double *alpha);
void central_difference(int64_t n, double dt_v, double dt, const double *mass, const double *a,
                        double *v, double *u, const double *f, double out[9],
                        double integral[3], double momentum[3], const int32_t *labels,
                        double *part_sums);
void shell_central_difference(int64_t n, double dt_v, double dt, const double *mass,
                              const double *a, double *v, double *u, const double *f,
                              double out[9], double integral[3], double momentum[3],
                              const int32_t *labels, double *part_sums, const double *inertia,
                              const double *turning, const double *alpha,
                              const double *moments, double *w, double turns[3]);
double interface_work(int64_t n, const int32_t *nodes, const double *f, const double *v);
typedef struct {
  int kind;
  double point[3], normal[3], dual[6], widths[2], axis[3], radius, fallback[3];
} wall_shape;
double numpy_sum(int64_t n, const double *a);
int64_t wall_find(int64_t n, const int64_t *near, const double *X, const double *u,
                  const double *v, const double *a, const double *mass, double dt_v, double dt,
                  const wall_shape *s, const double offset[3], const double next[3],
                  const double velocity[3], int64_t *hits, int64_t *nodes, double *m,
                  double *normals, double *vs, double *v_old, double *target);
void wall_impulses(int64_t k, int slide, double friction, double alpha, const double *m,
                   const double *n, const double *vs, const double velocity[3],
                   const double *target, const double *kept, double *normal,
                   double *tangential, uint8_t *slip);
void wall_work(int64_t k, const int64_t *nodes, const double *normal, const double *tangential,
               const double *v, const double velocity[3], double *scratch, double out[2]);
int wall_velocity(const double total[12], double mass, const double predicted[3],
                  const uint8_t held[3], double matrix[9], double rhs[3], double out[3]);
void largest_range(int64_t n, const double *v, const double *a, double out[2]);
void wall_apply(int64_t k, const int64_t *nodes, const double *m, const double *normal,
                const double *tangential, double dt_v, double *a, double out[9],
                const double *previous, const double before[3], double *scratch,
                double works[2]);
int wall_coupled(int64_t k, int tied, const uint8_t *slip, const double *m, const double *n,
                 const double *vs, const double *target, const double *tangential, double mass,
                 const double predicted[3], const uint8_t held[3], double out[27]);
void boundary_velocity(int64_t n, int64_t axes, const int32_t *nodes, const int64_t *flat,
                       const double *target, double dt_v, const double *mass, const double *v,
                       double *a, double *reaction, double *power, double *sums, int settle,
                       double works[2]);
void boundary_power(int64_t m, const int64_t *flat, const double *reaction, const double *v,
                    double *power);
void wall_coupling(int64_t k, int tied, const uint8_t *slip, const double *m, const double *n,
                   const double *vs, const double *target, const double *tangential,
                   double out[12]);
double wall_clearance(int64_t n, const int64_t *nodes, const double *X, const double *u,
                      const wall_shape *s, const double offset[3], double *clearance);
void largest_components(int64_t n, const int64_t *nodes, const double *v, const double *a,
                        double out[2]);
typedef struct {
  double gap, cap, friction, damping, alpha, dt, reach, moved, gap_max;
  const double *half_thickness;
  const double *node_size;
  const double *share;
  const int8_t *planes;
} contact_params;
double contact_moved(int64_t n, const double *x, const double *x0);
int64_t contact_sort(int64_t nsec, const int64_t *secondary, int64_t nseg, const int64_t *segs,
                     const double *reach, const double *x, const int64_t *removed_offsets,
                     const int64_t *removed, int64_t capacity, int64_t *offsets,
                     int64_t *candidates, int64_t *work);
int64_t contact_remove_lists(int64_t nseg, const int64_t *segs, int64_t nnodes, const double *x,
                             const int8_t *secondary, const double *seg_gap,
                             const double *seg_size, const double *node_gap,
                             const double *node_size, int variable, double gap, double gap_max,
                             int64_t capacity, int64_t *offsets, int64_t *removed);
int64_t contact_near(int64_t nsec, const int64_t *secondary, const int64_t *offsets,
                     const int64_t *candidates, const int64_t *segs, int64_t nused,
                     const int64_t *used, double *boxes, const double *x, double limit,
                     int64_t *near_offsets, int64_t *near, double *near_distance);
void contact_forces(int64_t nsec, const int64_t *secondary, const int64_t *offsets,
                    const int64_t *candidates, const double *listed, const int64_t *segs,
                    const double *stiffness0,
                    const double *depth, const double *size, const double *x, const double *v,
                    const double *mass, const contact_params *prm, double *tangential,
                    double *node_gap, double *force, double *stiffness, double out[11]);
void contact_initial_gaps(int64_t nsec, const int64_t *secondary, const int64_t *offsets,
                          const int64_t *candidates, const int64_t *segs,
                          const double *stiffness0, const double *depth,
                          const double *size, const double *x,
                          const contact_params *prm, double *node_gap, double out[3]);
void contact_read(int64_t n, const int64_t *rows, const double *X, const double *u,
                  const double *v, const double *mass, double *packed, double *x, double *vs,
                  double *ms, const double *kept, const double *sorted, const double *listed,
                  double out[3]);
void contact_unpack(int64_t n, const int64_t *order, const double *packed, double *x,
                    double *v, double *mass);
void contact_apply(int64_t n, const int64_t *rows, double *force, double *stiffness,
                   const double *ms, const double *mass, const double *v, double *a,
                   double *kept, const double *element, double out[2]);
double contact_power(int64_t n, const int64_t *rows, const double *kept, const double *v);
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


@dataclass(frozen=True)
class Extension:
    """C sources of this folder compiled together into one cffi extension module: its
    ``name`` (before the cache key), its ``sources`` (the headers it includes, then the
    ``.c`` files: all of them make the cache key), the declarations ``cdef`` that Python
    calls, and ``what`` it is, in words (for the line of a failed compile)."""

    name: str
    sources: tuple[str, ...]
    cdef: str
    what: str


ELEMENTS = Extension("_rwall_kernels", SOURCES, _CDEF, "the element kernels")
_UNWRITABLE: set[Path] = set()  # cache folders found unwritable (warned of once)


class KernelBuildError(RuntimeError):
    """The C compiler could not build compiled code (the element kernels, DOLFINx's forms);
    the message is one line."""


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


def _key(extension: Extension, flags: list[str]) -> str:
    import cffi

    digest = hashlib.sha256()
    here = Path(__file__).parent
    for name in extension.sources:
        digest.update((here / name).read_bytes())
    for part in (extension.cdef, " ".join(flags), sys.version, cffi.__version__, _cpu()):
        digest.update(part.encode())
    return digest.hexdigest()[:16]


def _import(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def _cached(name: str, folder: Path) -> Path | None:
    """A library ``<name>.<digest>.so`` of ``folder`` whose bytes have that digest: one cut
    short (a full disk, a kill while it was copied) or changed would fail to load, or
    crash the process with SIGBUS when a page of it is missing. A library that fails the
    check is removed if possible (libraries named otherwise, of older versions, are left
    to the processes that may use them)."""
    for path in sorted(folder.glob(f"{name}.*.so")):
        digest = path.name.removeprefix(f"{name}.").removesuffix(".so")
        if not re.fullmatch(r"[0-9a-f]{16}", digest):
            continue
        try:
            if _digest(path) == digest:
                return path
            path.unlink()
        except OSError:
            continue
    return None


def _writable(folder: Path) -> Path:
    """A new empty folder inside ``folder`` (made if needed) to build in; OSError if
    ``folder`` cannot be written (read-only, a file in its way, no space)."""
    folder.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=".build-", dir=folder))


def _build(extension: Extension, name: str, flags: list[str], folder: Path
           ) -> tuple[Path, Path | None]:  # fmt: skip
    """Compile ``extension`` as module ``name`` and publish the library in ``folder`` under
    its digest (one atomic rename: a concurrent process sees all of it or nothing). Returns
    its path, and the private temporary folder to remove once it is loaded when ``folder``
    cannot be written."""
    private = None
    try:
        work = _writable(folder)
    except OSError as err:
        if folder not in _UNWRITABLE:  # one warning a process, for all its extensions
            _UNWRITABLE.add(folder)
            log.warning(
                "the kernel cache %s cannot be written (%s): the kernels are compiled for "
                "this process only (set RWALL_FEM_CACHE to a folder it can write)",
                folder,
                err.strerror,
            )
        private = folder = Path(tempfile.mkdtemp(prefix="rwall_fem_kernels_"))
        work = _writable(folder)
    try:
        built = _compile(extension, name, flags, work)
        final = folder / f"{name}.{_digest(built)}.so"
        os.replace(built, final)
    except BaseException:
        if private is not None:
            shutil.rmtree(private, ignore_errors=True)
        raise
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return final, private


def _compile(extension: Extension, name: str, flags: list[str], work: Path) -> Path:
    """Compile ``extension`` as module ``name`` in the folder ``work``. What setuptools and
    the compiler say (each command; the compiler's warnings; the errors of a flag set it
    refuses, before the next set is tried) stays out of the run's output, in
    ``work/compiler.log``; a failure's message ends with the compiler's first error."""
    import cffi

    ffi = cffi.FFI()
    ffi.cdef(extension.cdef)
    here = Path(__file__).parent
    source = "".join(f'#include "{n}"\n' for n in extension.sources if n.endswith(".c"))
    ffi.set_source(name, source, include_dirs=[str(here)], extra_compile_args=flags)
    log = work / "compiler.log"
    try:
        with _output_to(log):
            return Path(ffi.compile(tmpdir=str(work), verbose=False))
    except Exception as err:
        said = [line.strip() for line in log.read_text(errors="replace").splitlines()
                if "error" in line]  # fmt: skip
        detail = str(err).strip().splitlines()[-1:] or [type(err).__name__]
        raise RuntimeError(" ".join(detail + said[:1])) from err


@contextlib.contextmanager
def _output_to(path: Path):
    """Python's standard output and error, and the file descriptors 1 and 2 that a
    compiler started meanwhile inherits, written to ``path`` for the duration."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(path, "w") as out:
            os.dup2(out.fileno(), 1)
            os.dup2(out.fileno(), 2)
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
                yield
    finally:
        for fd, kept in zip((1, 2), saved, strict=True):
            os.dup2(kept, fd)
            os.close(kept)


def compiler_error(what: str, detail: str) -> KernelBuildError:
    """The one line of a compilation of ``what`` that failed with ``detail``."""
    return KernelBuildError(
        f"could not compile {what} with the C compiler {os.environ.get('CC', 'cc')} "
        f"({detail}): install gcc (Debian: apt-get install gcc libc6-dev) or set CC to a C "
        "compiler"
    )


@cache
def load(extension: Extension = ELEMENTS):
    """The compiled ``extension`` (the solids' element kernels and the per-node passes by
    default) as ``(ffi, lib)``: the cached library if it passes its check, else built (a
    few seconds) and cached; without a cache that can be written, built for this process
    alone. :class:`KernelBuildError` (one line) when no flag set compiles."""
    failures = []
    for flags in FLAG_SETS:
        name = f"{extension.name}_{_key(extension, flags)}"
        path, private = _cached(name, _cache_dir()), None
        try:
            if path is None:
                path, private = _build(extension, name, flags, _cache_dir())
        except Exception as err:  # the compiler's failure, whatever setuptools wraps it in
            lines = str(err).strip().splitlines() or [type(err).__name__]
            failures.append(f"{' '.join(flags[:2])}: {lines[-1]}")
            continue
        try:
            module = _import(name, path)
        finally:
            if private is not None:  # the loaded library stays mapped
                shutil.rmtree(private, ignore_errors=True)
        return module.ffi, module.lib
    raise compiler_error(extension.what, "; ".join(failures))
