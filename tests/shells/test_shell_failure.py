"""Failure and erosion of shells, against the references of the solids'
(tests/verification/test_failure.py; docs/theory.md, "Shell bodies").

- A strip of shells pulled apart in its plane is in uniaxial stress (triaxiality 1/3):
  Johnson-Cook's rate- and temperature-free criterion fails it at the closed form
  eps_f = D1 + D2 exp(D3 / 3), to within the plastic strain of the step it fails in;
  the cells take the plastic work of linear hardening to eps_f and their elastic energy
  with them (eroded_internal), the live cells are left nothing, and the balance closes
  to round-off, as for solids.
- A plate struck through by a heavy sphere wall, its cells failing when 3 of their 5
  points have (element.failed_share = 0.6, Radioss's P_thickfail): cells erode, the
  detached nodes fly on, the books close to round-off, and 1 and 2 ranks erode the same
  cells with the same energies (to 1e-10).
"""

import copy
import math

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

comm = MPI.COMM_WORLD
D = {"d1": 0.05, "d2": 0.5, "d3": -1.5}
EPS_F = D["d1"] + D["d2"] * math.exp(D["d3"] / 3.0)  # 0.3533 at triaxiality 1/3
STEEL = {
    "model": "elastic_plastic", "density": 7850.0, "young": 200e9, "poisson": 0.3,
    "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e9,
}  # fmt: skip
LENGTH, WIDTH, THICK, H = 4e-3, 1e-3, 1e-4, 1e-3


def pull_scene(speed=1.2, failure=True, element=None):
    """A strip of 4 x 1 shells (1 mm, 0.1 mm thick) along x, its ends pulled apart in x at
    ``speed`` (m/s each) after a smoothstep ramp over 60 % of the pull, run a little past
    eps_f; its long sides free (uniaxial stress)."""
    rate = 2.0 * speed / LENGTH
    pull = 1.1 * math.expm1(EPS_F + 0.01) / rate
    ramp = 0.6 * pull
    table = [[ramp * x, speed * (3 * x**2 - 2 * x**3), 0.0, 0.0] for x in np.linspace(0, 1, 9)]
    material = dict(STEEL)
    if failure:
        material["failure"] = {"criterion": "johnson_cook", **D}
    raw = {
        "run": {"end_time": pull + 0.5 * ramp},
        "mesh": {"shape": "plate", "size": [LENGTH, WIDTH, THICK], "element_size": H,
                 "cell": "quadrilateral"},
        "material": material,
        "boundary": [
            {"group": "side_x0", "velocity": [[t, -v, 0, 0] for t, v, _, _ in table],
             "components": "x"},
            {"group": "side_x1", "velocity": table, "components": "x"},
        ],  # fmt: skip
        "output": {"plot": False, "frames": 0, "history_interval": 50},
    }
    if element:
        raw["element"] = element
    return raw


def test_a_pulled_strip_fails_at_the_closed_form_strain_and_keeps_its_books(shared_dir):
    raw = pull_scene(element={"thickness_change": True})  # the volume kept: the closed form's
    sim = build_simulation(parse_scene(raw, source="test"), comm, shared_dir)
    force = sim.internal.elements[0]
    seen = []  # (step, plastic strain) while the cells live

    class Watch:
        def due(self, s):
            return True

        def record(self, sim, s):
            if force.erosion.alive.all():
                seen.append(float(force.plastic_strains().max(initial=0.0)))

        def close(self, sim):
            pass

    sim.recorders.append(Watch())
    assert sim.run() == "done"
    summary = sim.history.summary
    energy = summary["energy"]
    cells = comm.allreduce(force.num_cells)
    assert summary["erosion"]["eroded_cells"] == cells
    last = comm.allreduce(seen[-1] if seen else 0.0, op=MPI.MAX)  # the strain before failing
    step = last - comm.allreduce(seen[-2] if len(seen) > 1 else 0.0, op=MPI.MAX)
    print(f"strip: failed past eps_p {last:.5f} (step {step:.2e}) against eps_f {EPS_F:.5f};"
          f" balance {energy['max_balance_error']:.2e}")
    assert EPS_F - 1.01 * step <= last < EPS_F
    A, Hm, E = STEEL["yield_stress"], STEEL["hardening_modulus"], STEEL["young"]
    stress = A + Hm * EPS_F
    volume = LENGTH * WIDTH * THICK
    expected = volume * (A * EPS_F + Hm * EPS_F**2 / 2 + stress**2 / (2 * E))
    print(f"strip: eroded_internal {energy['eroded_internal']:.6e} J against {expected:.6e} J")
    assert energy["eroded_internal"] == pytest.approx(expected, rel=3e-3)
    assert abs(energy["internal"]) <= 1e-3 * energy["eroded_internal"]
    for part in ("plastic_work", "elastic"):  # of the live cells: none
        assert abs(energy[part]) <= 1e-12 * energy["eroded_internal"]
    assert energy["max_balance_error"] <= 1e-12
