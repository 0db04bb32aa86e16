"""The shell study's solid reference: Richardson's extrapolation of three levels.

A figure f(h) = f0 + C h^p with h halved twice is extrapolated to f0 exactly, with the
order p observed and the finest level's distance from f0 (C h^p / f0); the grid
convergence index (Roache) is 1.25 times that distance. Levels that do not converge
monotonically (the change flips sign) are not extrapolated.
"""

import math

import pytest

from rwall_fem.study.shells import SAFETY, reference, richardson


@pytest.mark.parametrize("order", [1.0, 2.0, 1.37])
def test_richardson_recovers_the_limit_and_the_order_of_a_power_law(order):
    f0, c = 17.3, -4.1
    levels = [f0 + c * h**order for h in (0.4, 0.2, 0.1)]
    ref = richardson(levels)
    assert ref["extrapolated"]
    assert ref["order"] == pytest.approx(order, rel=1e-12)
    assert ref["value"] == pytest.approx(f0, rel=1e-12)
    distance = abs(c * 0.1**order / f0)
    assert ref["finest_error"] == pytest.approx(distance, rel=1e-10)
    assert ref["error"] == pytest.approx(SAFETY * distance, rel=1e-10)


def test_levels_that_oscillate_are_not_extrapolated():
    ref = richardson([10.0, 9.0, 9.5])
    assert not ref["extrapolated"]
    assert math.isnan(ref["order"])
    assert ref["value"] == 9.5  # the finest stands
    assert ref["error"] == pytest.approx(2 * 0.5 / 9.5)


def test_the_reference_takes_the_three_finest_solids_of_its_load():
    levels = [("plastic", "solid", 8e-3, 99.0), ("plastic", "solid", 4e-3, 4.0),
              ("plastic", "solid", 2e-3, 2.5), ("plastic", "shell", 2e-3, 7.0),
              ("plastic", "solid", 1e-3, 1.75), ("elastic", "solid", 5e-3, 5.0)]
    rows = [{"load": load, "kind": kind, "element_size": h, "peak_force": f, "contact_time": f,
             "deflection": f} for load, kind, h, f in levels]  # fmt: skip
    ref = reference(rows, "plastic")  # 4, 2.5, 1.75: order 1, limit 1
    assert ref["deflection"]["order"] == pytest.approx(1.0)
    assert ref["deflection"]["value"] == pytest.approx(1.0, rel=1e-12)
    single = reference(rows, "elastic")["peak_force"]
    assert (single["value"], single["extrapolated"]) == (5.0, False)


@pytest.mark.parametrize("order", [0.8, 2.0, 1.37])
def test_richardson_with_unequal_ratios_recovers_the_limit_and_the_order(order):
    # sizes 5, 2.5 and 5/3: ratios 2 then 1.5, as a third level of 1.667 mm x 6 layers
    f0, c = 17.3, 0.9
    sizes = (5.0, 2.5, 5.0 / 3.0)
    ref = richardson([f0 + c * h**order for h in sizes], sizes)
    assert ref["extrapolated"]
    assert ref["order"] == pytest.approx(order, rel=1e-10)
    assert ref["value"] == pytest.approx(f0, rel=1e-12)
    assert ref["finest_error"] == pytest.approx(abs(c * sizes[2] ** order / f0), rel=1e-9)
