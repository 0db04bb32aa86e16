"""Bodies of several parts (Radioss /PART, LS-DYNA *PART): materials and element
technologies by region of the mesh, bonded where they share nodes.

References: a body cut into two parts of one material is the body (to round-off: only
the order of the sums changes); a stress wave crossing from steel into aluminium is
transmitted by 2 Z2 / (Z1 + Z2) of the incident stress (Z = rho c, 1D wave theory, nu = 0)
after L1 / c1; the parts' books add up to the body's at every sample, and the body's
balance closes to round-off as for one part.
"""

import copy
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import StopAt, bar_scene, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.0}
ALUMINIUM = {"model": "linear_elastic", "density": 2700.0, "young": 70e9, "poisson": 0.0}
COPPER = {
    "model": "johnson_cook",
    "density": 8960.0,
    "young": 124e9,
    "poisson": 0.34,
    "yield_stress": 90e6,
    "hardening_coefficient": 292e6,
    "hardening_exponent": 0.31,
}


def columns(sim) -> dict[str, np.ndarray]:
    """The columns of the run's energy.csv by name (collective)."""
    return dict(zip(sim.history.balance.columns, sim.history.energy.T, strict=True))


def assert_parts_add_up(sim, names, tolerance=1e-12):
    """Every sample: the parts' kinetic, internal and hourglass energies add up to the
    body's, to ``tolerance`` x the largest energy (the walls carry no mass here)."""
    energy = columns(sim)
    scale = max(np.abs(energy[name]).max() for name in ("kinetic", "internal"))
    for name in ("kinetic", "internal", "hourglass"):
        if name not in energy:
            continue
        parts = sum(energy[f"{part}.{name}"] for part in names)
        assert np.abs(parts - energy[name]).max() <= tolerance * scale, name


def nosed_rod(end_time=8e-6):
    """A 4 x 4 x 16 mm steel rod with a 4 mm Johnson-Cook copper nose at 150 m/s onto a
    fixed plane, viscous hourglass control in the steel: a plastic part (its work booked
    at mid-step velocities, the interface forces kept by the kernels) and an adaptive step
    that falls as the nose is crushed."""
    return {
        "run": {"end_time": end_time},
        "mesh": {
            "shape": "bar",
            "size": [0.004, 0.004, 0.016],
            "element_size": 0.001,
            "front_length": 0.004,
        },
        "material": dict(STEEL, poisson=0.3),
        "element": {"hourglass": "viscous"},
        "initial": {"velocity": [0.0, 0.0, -150.0]},
        "part": [
            {"name": "nose", "volumes": ["front"], "material": COPPER},
            {"name": "rod", "volumes": ["body"]},
        ],
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 0, "plot": False},
    }


@pytest.mark.parametrize("cell", ["hexahedron", "tetrahedron"])
def test_two_parts_of_one_material_are_the_body(cell, shared_dir):
    """The bar cut at 10 of its 40 mm into two parts of its own material: every energy,
    the balance and the wall's impulse are the one-part run's to 1e-12 (round-off of sums
    taken in another order)."""
    raw = bar_scene(elements=40, h=1e-3, cell=cell)
    whole = run(raw, shared_dir / "whole")
    raw["mesh"]["front_length"] = 0.01
    raw["part"] = [{"name": "nose", "volumes": ["front"]}, {"name": "body"}]
    cut = run(raw, shared_dir / "cut")
    one, two = columns(whole), columns(cut)
    scale = whole.history.summary["energy"]["initial"]
    for name in one:
        assert np.abs(one[name] - two[name]).max() <= 1e-12 * max(scale, 1.0), name
    impulse = np.array(whole.history.summary["walls"][0]["impulse"])
    assert np.allclose(cut.history.summary["walls"][0]["impulse"], impulse, rtol=1e-12)
    assert_parts_add_up(cut, ("nose", "body"))


def test_a_wave_crosses_from_steel_into_aluminium(shared_dir):
    """A 60 mm bar, 20 mm of steel then aluminium (nu = 0, 1 mm cells), at 10 m/s onto a
    plane: the steel's strain energy grows at A sigma_I^2 / (2 Z1) with sigma_I = Z1 V,
    the aluminium's from t = L1 / c1 at A sigma_T^2 / (2 Z2), and sigma_T / sigma_I =
    2 Z2 / (Z1 + Z2) = 0.506 to 1 % (found 0.04 %); the reflected wave, behind which the
    steel holds sigma_I + sigma_R, gives sigma_R / sigma_I = (Z2 - Z1) / (Z1 + Z2) =
    -0.494 to 2 % (found 0.5 %); the transmitted front starts within one cell's transit
    (h / c2) of L1 / c1. Each part's energies add up to the body's."""
    h, front, rest, speed = 1e-3, 0.02, 0.04, 10.0
    c1, c2 = (math.sqrt(m["young"] / m["density"]) for m in (STEEL, ALUMINIUM))
    z1, z2 = STEEL["density"] * c1, ALUMINIUM["density"] * c2
    arrival = front / c1
    raw = {
        "run": {"end_time": arrival + rest / c2 - 0.3e-6},  # before the far end's echo
        "mesh": {
            "shape": "bar",
            "size": [h, h, front + rest],
            "element_size": h,
            "front_length": front,
        },
        "material": ALUMINIUM,
        "initial": {"velocity": [0.0, 0.0, -speed]},
        "part": [
            {"name": "steel", "volumes": ["front"], "material": STEEL},
            {"name": "aluminium", "volumes": ["body"]},
        ],
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 0, "plot": False},
    }
    sim = run(raw, shared_dir)
    energy = columns(sim)
    t, area = energy["time"], h * h
    incident = np.polyfit(*_window(t, energy["steel.internal"], 0.2 * arrival, 0.9 * arrival), 1)
    transmitted = np.polyfit(
        *_window(t, energy["aluminium.internal"], arrival + 1.5e-6, arrival + 6.5e-6), 1
    )
    # Behind the reflected front the steel holds sigma_I + sigma_R: its energy now falls.
    reflected = np.polyfit(
        *_window(t, energy["steel.internal"], arrival + 1.5e-6, 2.0 * arrival - 0.5e-6), 1
    )
    sigma_i = math.sqrt(2.0 * z1 * incident[0] / area)
    sigma_t = math.sqrt(2.0 * z2 * transmitted[0] / area)
    sigma_r = math.sqrt(sigma_i**2 + 2.0 * z1 * reflected[0] / area) - sigma_i
    assert sigma_i == pytest.approx(z1 * speed, rel=0.01)
    assert sigma_t / sigma_i == pytest.approx(2.0 * z2 / (z1 + z2), rel=0.01)
    assert sigma_r / sigma_i == pytest.approx((z2 - z1) / (z1 + z2), rel=0.02)
    assert abs(-transmitted[1] / transmitted[0] - arrival) <= h / c2
    assert_parts_add_up(sim, ("steel", "aluminium"))
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12


def _window(t, values, start, end):
    inside = (t > start) & (t < end)
    return t[inside], values[inside]


def test_a_plastic_nose_on_an_elastic_rod_keeps_its_books(shared_dir):
    """The copper nose crushed on the steel rod: the body's balance closes to round-off
    (1e-12) under a step that falls, the parts' energies add up to the body's at every
    sample, the plastic work is the nose's alone, and each part's mass is rho x its
    volume; the parts' momenta add up to the body's."""
    sim = run(nosed_rod(), shared_dir)
    summary = sim.history.summary
    assert summary["energy"]["max_balance_error"] <= 1e-12
    steps = columns(sim)["dt"]
    assert steps.min() < 0.75 * steps.max()
    assert_parts_add_up(sim, ("nose", "rod"))
    nose, rod = summary["parts"]
    assert nose["energy"]["plastic_work"] == pytest.approx(summary["plastic_work"], rel=1e-12)
    assert nose["max_plastic_strain"] > 0.3 and "plastic_work" not in rod["energy"]
    area = 0.004 * 0.004
    assert nose["mass"] == pytest.approx(COPPER["density"] * area * 0.004, rel=1e-12)
    assert rod["mass"] == pytest.approx(STEEL["density"] * area * 0.012, rel=1e-12)
    momenta = np.add(nose["momentum"], rod["momentum"])
    assert np.allclose(momenta, summary["final_momentum"], rtol=1e-12, atol=1e-12)
    assert (nose["cells"], rod["cells"]) == (64, 192)


def test_a_resumed_run_of_parts_equals_the_uninterrupted_one(shared_dir):
    """Stopped mid-crush and resumed from its checkpoint: the parts' books (the works of
    the plastic nose and of the viscous rod, the interface forces pending their second
    half) carry over, and every output is the uninterrupted run's to the last bit."""
    raw = nosed_rod()
    raw["output"]["checkpoint_steps"] = 10
    whole = run(raw, shared_dir / "whole")
    out = shared_dir / "stopped"
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD, out)
    sim.recorders.append(StopAt(30))
    assert sim.run().startswith("stopped: step 30,")
    resumed = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD, out)
    resumed.checkpoints.resume(resumed)
    assert resumed.run() == "done"
    assert np.array_equal(resumed.state.u, whole.state.u)
    MPI.COMM_WORLD.Barrier()
    if MPI.COMM_WORLD.rank == 0:
        assert (out / "energy.csv").read_text() == (shared_dir / "whole" / "energy.csv").read_text()


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a partitioned run with a serial one")
def test_parts_do_not_depend_on_the_ranks(shared_dir, tmp_path):
    """The nosed rod on 2 ranks (parts and interfaces cut by the partition) against one:
    every column of energy.csv, the parts' included, to 1e-10 of the initial energy."""
    raw = nosed_rod(end_time=4e-6)
    parallel = run(raw, shared_dir)
    serial = run(raw, tmp_path, comm=MPI.COMM_SELF)
    par, ser = columns(parallel), columns(serial)
    assert par.keys() == ser.keys() and len(par["time"]) == len(ser["time"])
    scale = serial.history.summary["energy"]["initial"]
    for name in par:
        assert np.abs(par[name] - ser[name]).max() <= 1e-10 * scale, name


def test_a_wall_takes_the_nodes_of_a_part(shared_dir):
    """secondary.parts: the nodes of the named parts, the interface's included: the 4 mm
    nose of 1 mm cells on a 4 x 4 mm section holds 5 x 5 x 5 nodes, the rod 5 x 5 x 13."""
    raw = nosed_rod(end_time=1e-7)
    raw["wall"] = [
        {"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1],
         "secondary": {"parts": ["nose"]}},
        {"kind": "plane", "point": [0, 0, 0.1], "normal_point": [0, 0, 0],
         "secondary": {"parts": ["rod"]}},
    ]  # fmt: skip
    sim = run(raw, shared_dir)
    counts = [wall["secondary_nodes"] for wall in sim.history.summary["walls"]]
    assert counts == [125, 325]


def test_fields_carry_the_part_of_each_cell(shared_dir):
    """fields.xdmf holds the cell field "part" (the part's index): 64 cells of the nose
    (0) and 192 of the rod (1), beside the plastic strain and von Mises stress. (h5py
    reads the file in a process of its own: its HDF5 and DOLFINx's do not share one.)"""
    raw = nosed_rod(end_time=1e-7)
    raw["output"]["fields"] = 1
    run(raw, shared_dir)
    MPI.COMM_WORLD.Barrier()
    if MPI.COMM_WORLD.rank != 0:
        return
    code = (
        "import sys, json, h5py, numpy as np\n"
        "with h5py.File(sys.argv[1]) as h5:\n"
        "    (part,) = h5['Function']['part'].values()\n"
        "    print(json.dumps([sorted(h5['Function']),"
        " np.bincount(np.asarray(part).ravel().astype(int)).tolist()]))\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    result = subprocess.run(
        [sys.executable, "-c", code, str(shared_dir / "fields.h5")],
        env=env, capture_output=True, text=True, check=True,
    )  # fmt: skip
    names, counts = json.loads(result.stdout)
    assert {"part", "plastic_strain", "von_mises_stress"} <= set(names)
    assert counts == [64, 192]
