"""A quarter of a plate with its symmetry planes equals the whole plate, in J2 plasticity.

The clamped 200 x 200 x 2 mm steel plate of the shell study (``rwall_fem.study.shells``)
struck at its centre at 20 m/s by a sphere wall on a main node, at 10 mm cells for 2 ms:
as the plastic plate wraps round the sphere, nodes off its centre touch it. Their pushes
on the sphere cancel in the whole plate; in a quarter they all point away from the quarter
and must go to the symmetry planes: the sphere's main node lies on both, so its x and y
velocity are held (``motion.held = "xy"``). Then the quarter (a quarter of the sphere's
mass, u_x = 0 and rotations about y and z held on x = 0, likewise on y = 0) gives the
whole plate's sphere velocity, plastic work and internal energy to round-off (1e-12),
on any number of ranks. The sphere free in x and y drifts off the centre instead (-2.5 m/s
in x and in y by 2 ms here) and rebounds at 0.67 m/s instead of 4.52: the test sees that too.
"""

import pytest
from conftest import run
from mpi4py import MPI

from rwall_fem.study import shells

comm = MPI.COMM_WORLD
H, END = 0.01, 2.0e-3  # m, s


def _plate(directory, quarter: bool, held: str | None = "xy") -> dict:
    raw = shells.plate_scene("plastic", "shell", H, 0, directory)
    raw["run"]["end_time"] = END
    if quarter:
        raw["mesh"] |= {"origin": [0.0, 0.0, -0.001], "size": [0.1, 0.1, 0.002]}
        raw["boundary"] = [
            {"group": "side_x0", "components": "x", "rotations": "yz"},
            {"group": "side_y0", "components": "y", "rotations": "xz"},
            {"group": "side_x1", "components": "xyz", "rotations": "xyz"},
            {"group": "side_y1", "components": "xyz", "rotations": "xyz"},
        ]
        raw["wall"][0]["motion"]["mass"] = 0.25
        if held:
            raw["wall"][0]["motion"]["held"] = held
    sim = run(raw, directory)
    s = sim.history.summary
    share = 4.0 if quarter else 1.0
    return {
        "velocity": s["walls"][0]["velocity"],
        "plastic_work": share * s["energy"]["plastic_work"],
        "internal": share * s["energy"]["internal"],
        "balance": s["energy"]["max_balance_error"],
    }


def test_a_quarter_plate_equals_the_whole_plate_in_j2(tmp_path_factory):
    def folder(name):
        return comm.bcast(tmp_path_factory.mktemp(name) if comm.rank == 0 else None, root=0)

    whole = _plate(folder("whole"), quarter=False)
    quarter = _plate(folder("quarter"), quarter=True)
    assert whole["velocity"][2] > 4.0  # it rebounds (from -20 m/s)
    assert whole["plastic_work"] > 100.0  # J, of the 200 J of the impact: plastic indeed
    assert quarter["velocity"][:2] == [0.0, 0.0]
    assert quarter["velocity"][2] == pytest.approx(whole["velocity"][2], rel=1e-12)
    for name in ("plastic_work", "internal"):
        assert quarter[name] == pytest.approx(whole[name], rel=1e-12), name
    assert max(whole["balance"], quarter["balance"]) < 1e-6
    free = _plate(folder("free"), quarter=True, held=None)
    assert free["velocity"][0] < -1.0 and free["velocity"][1] < -1.0
    assert abs(free["velocity"][2] / whole["velocity"][2] - 1.0) > 0.05
