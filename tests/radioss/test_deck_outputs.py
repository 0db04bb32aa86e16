"""What a deck's user reads: energy.csv, walls.csv and summary.json in the deck's work
units (output.units = "deck"), checked against the SI run with factors worked out here by
hand; one warning when the declared units do not fit the materials; a starter listing
from ``rwall-fem check`` (parts, masses, the smallest element steps, walls); a law's
failure strain and /FAIL/JOHNSON as [material.failure]."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import parse_scene
from rwall_fem.output.wall_table import WALL_COLUMNS
from rwall_fem.radioss import read_deck
from rwall_fem.radioss.plausible import unit_warning

from .decks import BarDeck, f20, steel
from .test_deck_controls import loaded
from .test_deck_scenes import deck_scene, plastic_deck, run

# kg-mm-ms in SI, by hand: the factors that take an SI value into these units.
TO_KG_MM_MS = {"time": 1e3, "energy": 1.0, "force": 1e-3, "impulse": 1.0, "length": 1e3,
               "velocity": 1.0, "mass": 1.0}  # fmt: skip


def test_outputs_in_the_deck_units(shared_dir):
    d = plastic_deck("kg-mm-ms")
    si = run(deck_scene(d, shared_dir, ["output.plot=false"]), shared_dir / "si")
    deck = run(deck_scene(d, shared_dir, ["output.plot=false", "output.units=deck"]),
               shared_dir / "deck")  # fmt: skip
    a, b = si.history.energy, deck.history.energy  # read back from the files
    columns = si.history.balance.columns
    for k, name in enumerate(columns):
        factor = TO_KG_MM_MS["time"] if name in ("time", "dt") else 1.0
        assert np.allclose(b[:, k], a[:, k] * factor, rtol=1e-14, atol=0), name
    rows_si = si.history.wall(1)
    rows = deck.history.wall(1)
    quantity = {"time": "time", "force": "force", "normal": "force", "tangential": "force",
                "impulse": "impulse", "position": "length", "velocity": "velocity"}  # fmt: skip
    for k, name in enumerate(WALL_COLUMNS):
        head = name.split("_")[0]
        factor = TO_KG_MM_MS[quantity[head]] if head in quantity else 1.0
        if "impulse" in name:
            factor = 1.0
        assert np.allclose(rows[:, k], rows_si[:, k] * factor, rtol=1e-14, atol=0), name
    if MPI.COMM_WORLD.rank == 0:
        written = json.loads((shared_dir / "deck" / "summary.json").read_text())
        ref = si.history.summary  # in memory: SI
        assert written["units"] == {"mass": "kg", "length": "mm", "time": "ms",
                                    "in_SI": [1.0, 1e-3, 1e-3]}  # fmt: skip
        assert written["time"] == pytest.approx(ref["time"] * 1e3, rel=1e-14)
        assert written["walls"][1]["position"] == pytest.approx(
            [x * 1e3 for x in ref["walls"][1]["position"]], rel=1e-14)  # fmt: skip
        assert written["deformed_bounds"][1][2] == pytest.approx(
            ref["deformed_bounds"][1][2] * 1e3, rel=1e-14)  # fmt: skip
        assert written["energy"]["kinetic"] == pytest.approx(ref["energy"]["kinetic"])
        assert written["steps"] == ref["steps"] and written["wall_seconds"] > 0


def test_output_units_of_a_toml_scene():
    raw = {"run": {"end_time": 1e-5}, "material": {"model": "linear_elastic", **steel()},
           "output": {"units": "Mg-mm-s"}}  # fmt: skip
    assert parse_scene(raw, source="t").output.units == "Mg-mm-s"


def test_units_that_do_not_fit_get_one_warning(shared_dir):
    """A deck of kg, mm, ms numbers declared in kg, m, s: its steel would be 7.85e-6 kg/m^3,
    no solid; the warning names kg-mm-ms. The same deck declared right has none."""
    d = BarDeck(units="kg-mm-ms", nz=2)
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    path = d.write(shared_dir) if MPI.COMM_WORLD.rank == 0 else None
    path = MPI.COMM_WORLD.bcast(path, root=0)
    right = unit_warning(read_deck(path))
    MPI.COMM_WORLD.barrier()  # every rank has read it before rank 0 rewrites it
    assert right is None
    if MPI.COMM_WORLD.rank == 0:
        text = path.read_text().replace(f"{'kg':>20}{'mm':>20}{'ms':>20}",
                                        f"{'kg':>20}{'m':>20}{'s':>20}")  # fmt: skip
        path.write_text(text)
    MPI.COMM_WORLD.barrier()
    warning = unit_warning(read_deck(path))
    assert warning.startswith(f"{path}:2: /BEGIN: the input units kg-m-s do not fit the deck")
    assert "has a density of 7.85e-06 kg/m^3" in warning
    assert warning.endswith("its numbers fit kg-mm-ms or g-mm-ms")


@pytest.mark.serial
def test_check_prints_a_starter_listing(tmp_path):
    """Two parts of 4 and 12 cubes of 1 mm (steel, aluminium): their masses rho V, and the
    smallest element step h / c, c = sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu))), of the
    aluminium, whose c is the larger; the wall's secondary nodes."""
    d = BarDeck(units="kg-mm-ms", nz=4, front=1)
    d.part(mat=1, prop=1, pid=1, title="steel rod")
    d.part(mat=2, prop=1, pid=2, title="nose")
    d.elastic(7850.0, 210e9, 0.3, mid=1)
    d.elastic(2700.0, 70e9, 0.33, mid=2)
    d.solid(24)
    d.group(1, "PART", [1, 2])
    d.initial_velocity((0, 0, -5.0), 1)
    d.wall("PLANE", m1=(0, 0, 1), dsearch=1e-4)
    path = d.write(tmp_path)
    done = subprocess.run([sys.executable, "-m", "rwall_fem", "check", str(path)],
                          capture_output=True, text=True)  # fmt: skip
    assert done.returncode == 0, done.stderr
    out = done.stdout.splitlines()
    rows = {int(line.split()[0]): line.split() for line in out
            if line.split()[:1] in (["1"], ["2"]) and "/BRICK" in line}  # fmt: skip
    assert float(rows[1][3]) == pytest.approx(7850.0 * 12e-9, rel=1e-5)
    assert float(rows[2][3]) == pytest.approx(2700.0 * 4e-9, rel=1e-5)
    assert rows[1][1:3] == ["12", "/BRICK"] and rows[2][1:3] == ["4", "/BRICK"]
    c = math.sqrt(70e9 * 0.67 / (2700.0 * 1.33 * 0.34))
    smallest = next(line for line in out if line.strip().startswith(f"{1e-3 / c:.4g} s:"))
    assert "(/BRICK, part 2)" in smallest
    assert any("wall[0] /RWALL/PLANE/1" in line and "9 secondary nodes" in line for line in out)


def test_failure_strain_and_fail_johnson_become_material_failure(shared_dir):
    """Issue 28, class 6: /MAT/LAW2's EPS_p_max is [material.failure] with a constant
    plastic strain (Radioss deletes the element there), /FAIL/JOHNSON D1-D5 the
    johnson_cook criterion; a deck with both is refused in one line."""
    d = plastic_deck("kg-mm-ms")
    k = d.cards.index("/MAT/LAW2/1")
    d.cards[k : k + 7] = []
    d.johnson_cook(8930.0, 117e9, 0.35, a=400e6, b=100e6, n=0.5, c=0.01, rate0=1.0,
                   eps_max=0.35)  # fmt: skip
    scene, _ = loaded(d, shared_dir)
    failure = scene.material.failure
    assert (failure.criterion, failure.plastic_strain) == ("plastic_strain", 0.35)
    d.cards[-3] = d.cards[-3][:60] + f20(0.0) + d.cards[-3][80:]  # EPS_p_max blank
    d.cards += ["/FAIL/JOHNSON/1", f20(0.05) + f20(3.44) + f20(-2.12) + f20(0.002) + f20(0.61),
                f20(1e-3)]  # per ms: 1 /s  # fmt: skip
    scene, _ = loaded(d, shared_dir)
    failure = scene.material.failure
    assert failure.criterion == "johnson_cook"
    assert (failure.d1, failure.d2, failure.d3, failure.d4, failure.d5) == (
        0.05, 3.44, -2.12, 0.002, 0.61)  # fmt: skip
    assert failure.reference_strain_rate == pytest.approx(1.0, rel=1e-12)
