"""The study's cost model: log-log interpolation and extrapolation of error against time."""

import numpy as np
import pytest

from rwall_fem.study import cost_at


def test_cost_interpolates_in_log_log():
    # error = t^-1/4: 1 % at t = 1e8 / 1e0 ... exact power law, so interpolation is exact.
    t = np.array([1.0, 16.0, 256.0])
    e = 0.04 * t**-0.25
    seconds, cells, how = cost_at(e, t, 100 * t, 0.01)
    assert how == "interpolated"
    assert seconds == pytest.approx(256.0)
    assert cells == pytest.approx(25600.0)
    seconds, _, how = cost_at(e, t, 100 * t, 0.005)
    assert how == "extrapolated"
    assert seconds == pytest.approx(4096.0)
