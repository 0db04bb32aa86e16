"""ns per element-step of the shell kernels against the one-point J2 hexahedron kernel.

    python bench/shell_kernels.py [cells ...]

Each kernel runs over a structured grid of the given number of cells (default 10,000 and
100,000) with small random velocities, as in a step of a run, on one core; the best of
several repeats (processor time: the machine may be shared) is reported. The J2 cases
(power-law hardening) flow plastically at every
point once the first steps have brought the stresses to the yield surface (a steady
plastic flow, increments of about 4e-5 per step), hexahedra alike; "elastic" is the same
law below its yield stress.
"""

from __future__ import annotations

import math
import sys
import time
from types import SimpleNamespace

import numpy as np

from rwall_fem.kernels import STEP_SLOTS, load
from rwall_fem.shells.elements import ShellKernel, ShellTechnology

E, NU, RHO = 210e9, 0.3, 7850.0
J2 = dict(model="elastic_plastic", plastic=True, young=E, poisson=NU, density=RHO,
          hardening="power", yield_stress=300e6, hardening_coefficient=500e6,
          hardening_exponent=0.3, strain_rate_coefficient=0.0, reference_strain_rate=1.0,
          failure=None, heating=None)  # fmt: skip


WARM_UP = 80  # steps of the same increments: the stresses reach the yield surface and flow


def best(call, repeats=7):
    times = []
    for _ in range(repeats):
        start = time.process_time()
        call()
        times.append(time.process_time() - start)
    return min(times)


def shell_case(cells_wanted: int, plastic: bool, points: int = 5, yield_stress=300e6,
               cell="quadrilateral"):
    n = int(round(math.sqrt(cells_wanted / (2 if cell == "triangle" else 1))))
    h = 2.5e-3
    s = np.arange(n + 1) * h
    X = np.array([[x, y, 0.0] for y in s for x in s])
    row = n + 1
    cells = np.array([[j * row + i, j * row + i + 1, (j + 1) * row + i + 1, (j + 1) * row + i]
                      for j in range(n) for i in range(n)], np.int32)  # fmt: skip
    if cell == "triangle":  # each square halved
        cells = np.ascontiguousarray(np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]]))
    rng = np.random.default_rng(0)
    if plastic:
        material = SimpleNamespace(**(J2 | {"yield_stress": yield_stress}))
    else:
        material = SimpleNamespace(model="linear_elastic", plastic=False, young=E, poisson=NU,
                                   density=RHO)  # fmt: skip
    k = ShellKernel(material, ShellTechnology.choose(cell, points=points), cells, 1e-3)
    u = rng.normal(size=X.shape) * 1e-6
    v, w = rng.normal(size=X.shape), rng.normal(size=X.shape) * 100
    f, m = np.zeros_like(X), np.zeros_like(X)
    energy, step = np.zeros(4), np.zeros(STEP_SLOTS)
    k.params.dt, k.params.estimate = 1e-7, 1
    call = k.bind(len(cells), X, u, v, w, f, m, energy, step)
    for _ in range(WARM_UP):
        call()
    if plastic and yield_stress < 1e9:
        print(f"  points flowing: {np.mean(k.plastic_strains() > 0):.0%}")
    return len(cells), call


def hex_case(cells_wanted: int):
    ffi, lib = load()
    n = int(round(cells_wanted ** (1 / 3)))
    h = 2.5e-3
    s = np.arange(n + 1) * h
    X = np.array([[x, y, z] for z in s for y in s for x in s])
    N = n + 1
    cells = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                base = [(k + c) * N * N + (j + b) * N + (i + a)
                        for c in (0, 1) for b in (0, 1) for a in (0, 1)]  # fmt: skip
                cells.append(base)
    cells = np.array(cells, np.int32)
    rng = np.random.default_rng(0)
    u, v = rng.normal(size=X.shape) * 1e-6, rng.normal(size=X.shape)
    f, energy, step = np.zeros_like(X), np.zeros(4), np.zeros(STEP_SLOTS)
    p = ffi.new("element_params *")
    p.lmbda, p.mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    p.density, p.wave_speed = RHO, math.sqrt((p.lmbda + 2 * p.mu) / RHO)
    p.hourglass_coefficient, p.calibration, p.dt, p.estimate = 0.1, 1.0, 1e-7, 1
    p.hardening, p.yield_stress = 1, 300e6
    p.hardening_coefficient, p.hardening_exponent = 500e6, 0.3
    volume0 = np.full(len(cells), h**3)
    p.volume0 = ffi.cast("double *", volume0.ctypes.data)
    state = np.zeros((8 + 12, len(cells)))

    def ptr(a, kind="double *"):
        return ffi.cast(kind, a.ctypes.data)

    def call():
        lib.hex8r_plastic_viscous(len(cells), ptr(cells, "int32_t *"), ptr(X), ptr(u), ptr(v),
                                  p, ptr(state), len(cells), ptr(f), ptr(energy),
                                  ptr(step))  # fmt: skip

    for _ in range(WARM_UP):
        call()
    print(f"  hexahedra flowing: {np.mean(state[6] > 0):.0%}")

    return len(cells), call, volume0


def main(sizes):
    print(f"{'kernel':34s} {'cells':>8s} {'ns/element-step':>16s}")
    for size in sizes:
        rows = []
        cases = (
            ("shell quad elastic", lambda: shell_case(size, False)),
            ("shell quad J2, 5 points", lambda: shell_case(size, True)),
            ("shell quad J2, 3 points", lambda: shell_case(size, True, 3)),
            ("shell quad J2, 5 points, elastic", lambda: shell_case(size, True, 5, 1e12)),
            ("shell triangle elastic", lambda: shell_case(size, False, cell="triangle")),
            ("shell triangle J2, 5 points", lambda: shell_case(size, True, cell="triangle")),
        )
        for name, case in cases:
            cells, call = case()
            rows.append((name, cells, best(call) / cells * 1e9))
        cells, call, _keep = hex_case(size)
        rows.append(("hexahedron 1-point J2 (viscous)", cells, best(call) / cells * 1e9))
        for name, cells, ns in rows:
            print(f"{name:34s} {cells:8d} {ns:16.1f}")
        print(f"  J2 5-point quad / J2 hexahedron: {rows[1][2] / rows[-1][2]:.2f}")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [10_000, 100_000])
