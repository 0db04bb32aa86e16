"""A cell's results do not depend on how many cells a kernel computes at once
(``LANES`` of ``kernels/batch.h``: 8 on hosts with AVX-512, 4 elsewhere).

The P1 tetrahedron kernels (``kernels/tetrahedron.c``: batch.h's gather, scatter and state
rows, its short last batch and its lists of live cells) are compiled twice, for this host
(``-march=native``) and for x86-64-v3 (AVX2 and FMA, no AVX-512: 4 lanes, the build of a
host without AVX-512), and run on the same cells. The elastic laws' nodal forces and
element steps agree to the bit, their energies (summed batch by batch) to 1e-14 of their
size. The elasto-plastic kernel's return iterates until every lane of its batch has
converged (``plasticity.h``), so that a converged lane may take one more Newton step that
moves it by round-off: its forces, energies and state agree to 1e-13 of their size, its
steps to the bit. Without this test the 4-lane build would go untested on an AVX-512
machine (it was once 8 lanes everywhere, unnoticed).
"""

from __future__ import annotations

import platform
import re
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import kernels
from rwall_fem.kernels import ELEMENT_PARAMS, STEP_SLOTS, Extension

E, NU, RHO = 210e9, 0.3, 7850.0
POINT_ROWS = kernels.POINT_SLOTS + 1  # a point's state and the damage row (failure.h)
MODELS = kernels.MODELS

_CDEF = (
    ELEMENT_PARAMS
    + "\n"
    + "".join(
        f"void tet4_{m}(int64_t n, const int32_t *cells, const double *X, const double *u,"
        " const element_params *p, double *f, double *energy, double *step);\n"
        for m in MODELS
    )
    + "void tet4_plastic(int64_t n, const int32_t *cells, const double *X, const double *u,"
    " const double *v, const element_params *p, double *state, int64_t stride, double *f,"
    " double *energy, double *step);\n"
)
TETRAHEDRA = Extension(
    "_rwall_lanes_test",
    ("batch.h", "materials.h", "plasticity.h", "step.h", "failure.h", "tetrahedron.c"),
    _CDEF,
    "the tetrahedron kernels",
)
AVX2 = ["-O3", "-march=x86-64-v3", "-fopenmp-simd", "-fno-math-errno", "-fvisibility=hidden"]


def _host_has(flag: str) -> bool:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return False
    return re.search(rf"^flags\s*:.*\b{flag}\b", text, re.M) is not None


pytestmark = [
    pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="compiles and compares on one process"),
    pytest.mark.skipif(platform.machine() != "x86_64" or not _host_has("avx2"),
                       reason="an x86-64 host with AVX2 runs both builds"),  # fmt: skip
]


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    """(ffi, lib) of the tetrahedron kernels for this host, then for x86-64-v3."""
    out = []
    for tag, flags in (("native", kernels.FLAG_SETS[0]), ("avx2", AVX2)):
        folder = tmp_path_factory.mktemp(tag)
        path, _ = kernels._build(TETRAHEDRA, f"{TETRAHEDRA.name}_{tag}", flags, folder)
        module = kernels._import(f"{TETRAHEDRA.name}_{tag}", path)
        out.append((module.ffi, module.lib))
    return out


def _mesh(n: int = 3):
    """A box of n x n x 2 cubes (edge 1 mm), six tetrahedra each (positively oriented), its
    nodes moved a little at random: (X, cells)."""
    rng = np.random.default_rng(7)
    s = np.arange(n + 1) * 1e-3
    X = np.array([[x, y, z] for z in s[:3] for y in s for x in s])
    X += rng.uniform(-1e-4, 1e-4, X.shape)
    N = n + 1

    def node(i, j, k):
        return k * N * N + j * N + i

    six = [(0, 1, 3, 7), (0, 1, 7, 5), (0, 4, 5, 7), (0, 2, 6, 7), (0, 3, 2, 7), (0, 6, 4, 7)]
    cells = []
    for k in range(2):
        for j in range(n):
            for i in range(n):
                corner = [node(i + a, j + b, k + c) for c in (0, 1) for b in (0, 1) for a in (0, 1)]
                cells += [[corner[q] for q in t] for t in six]
    cells = np.array(cells, dtype=np.int32)
    e = X[cells]
    edges = e[:, 1:] - e[:, :1]
    volume = np.einsum("ij,ij->i", np.cross(edges[:, 0], edges[:, 1]), edges[:, 2])
    swap = volume < 0
    cells[swap] = cells[swap][:, [0, 2, 1, 3]]
    return X, np.ascontiguousarray(cells)


def _params(ffi, keep: list, cells: np.ndarray, plastic: bool, live: np.ndarray | None):
    p = ffi.new("element_params *")
    lmbda, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    p.lmbda, p.mu, p.density = lmbda, mu, RHO
    p.wave_speed = np.sqrt((lmbda + 2 * mu) / RHO)
    p.dt, p.calibration, p.estimate = 1e-7, 1.0, 1
    length0, volume0 = np.full(len(cells), 1e-3), np.full(len(cells), 1e-9 / 6)
    keep += [length0, volume0]
    p.length0 = ffi.from_buffer("double[]", length0)
    p.volume0 = ffi.from_buffer("double[]", volume0)
    if plastic:
        p.hardening, p.yield_stress = 1, 300e6
        p.hardening_coefficient, p.hardening_exponent = 500e6, 0.3
        p.damage_slot = kernels.POINT_SLOTS
    if live is not None:
        keep.append(live)
        p.live = ffi.from_buffer("int32_t[]", live)
    return p


def _run(build, kernel: str, X, cells, u, v, live, steps: int):
    """Forces, energies, steps and state after ``steps`` calls of ``kernel`` (u moved by
    dt v between calls)."""
    ffi, lib = build
    keep: list = []
    plastic = kernel == "plastic"
    p = _params(ffi, keep, cells, plastic, live)
    n = len(cells) if live is None else len(live)
    state = np.zeros((POINT_ROWS, len(cells)))
    u = u.copy()
    for _ in range(steps):
        f, energy, step = np.zeros_like(X), np.zeros(4), np.zeros(STEP_SLOTS)
        ptr = ffi.from_buffer
        common = (n, ptr("int32_t[]", cells), ptr("double[]", X), ptr("double[]", u))
        if plastic:
            lib.tet4_plastic(*common, ptr("double[]", v), p, ptr("double[]", state),
                             len(cells), ptr("double[]", f), ptr("double[]", energy),
                             ptr("double[]", step))  # fmt: skip
        else:
            getattr(lib, f"tet4_{kernel}")(*common, p, ptr("double[]", f), ptr("double[]", energy),
                                           ptr("double[]", step))
        u += p.dt * v
    return f, energy, step, state


@pytest.mark.parametrize("kernel", [*MODELS, "plastic"])
@pytest.mark.parametrize("listed", [False, True], ids=["all cells", "a list of live cells"])
def test_four_and_eight_lanes_give_each_cell_the_same_results(builds, kernel, listed):
    """The same cells (108, not a multiple of 8: a short last batch; or a shuffled list of
    61 of them, batches of cells that are not consecutive) through both builds, 40 steps
    of the plastic kernel in flow (its plastic strains are checked to be nonzero, so that
    the return ran): equal as the module says."""
    X, cells = _mesh()
    rng = np.random.default_rng(3)
    u = rng.normal(size=X.shape) * 2e-6
    v = rng.normal(size=X.shape) * 30.0
    live = np.sort(rng.permutation(len(cells))[:61]).astype(np.int32) if listed else None
    if live is not None:
        rng.shuffle(live)
    steps = 40 if kernel == "plastic" else 1
    native, avx2 = (_run(b, kernel, X, cells, u, v, live, steps) for b in builds)
    round_off = 1e-13 if kernel == "plastic" else 0.0
    for name, a, b in zip(("forces", "energy", "steps", "state"), native, avx2, strict=True):
        if name == "energy":
            np.testing.assert_allclose(a, b, rtol=0, atol=max(round_off, 1e-14) * np.abs(a).max())
        elif name == "steps" or not round_off:
            np.testing.assert_array_equal(a, b, err_msg=name)
        else:  # row by row (the state's rows have their own scales)
            a2, b2 = np.atleast_2d(a), np.atleast_2d(b)
            scale = np.abs(a2).max(axis=1, keepdims=True)
            assert np.all(np.abs(a2 - b2) <= round_off * scale), name
    if kernel == "plastic":
        assert np.count_nonzero(native[3][6]) > 0.5 * (len(cells) if live is None else len(live))


def _lanes(flags: list[str], folder: Path) -> int:
    """LANES as batch.h defines it under the compiler flags ``flags``."""
    import cffi

    ffi = cffi.FFI()
    ffi.cdef("int lanes(void);")
    name = f"_rwall_lanes_probe_{folder.name}"
    ffi.set_source(name, '#include "batch.h"\nint lanes(void) { return LANES; }',
                   include_dirs=[str(Path(kernels.__file__).parent)], extra_compile_args=flags)
    path = ffi.compile(tmpdir=str(folder), verbose=False)
    return kernels._import(name, Path(path)).lib.lanes()


def test_eight_lanes_with_avx512_four_without(tmp_path):
    """batch.h computes 8 cells at once where the compiler targets AVX-512 (this host's
    build, if it has it) and 4 elsewhere (x86-64-v3)."""
    assert _lanes(kernels.FLAG_SETS[0], tmp_path / "native") == (8 if _host_has("avx512f") else 4)
    assert _lanes(AVX2, tmp_path / "avx2") == 4
