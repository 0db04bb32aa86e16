"""Two elastic spheres colliding head-on, against Hertz's theory (issue 30).

Two equal steel spheres (R = 10 mm, E = 200 GPa, nu = 0.3) meet at +-v through a
symmetric, undamped, frictionless contact. Hertz (Johnson, Contact Mechanics, 11.4):
with m* = m/2, R* = R/2, E* = E / (2 (1 - nu^2)) and the closing speed V = 2v, the
contact lasts t_c = 2.868 (m*^2 / (R* E*^2 V))^(1/5) and the force peaks at
F = 4/3 E* sqrt(R*) d^(3/2), d = (15 m* V^2 / (16 E* sqrt(R*)))^(2/5) the largest
approach. Hertz is quasi-static (t_c is 10-11 times the spheres' wave transit 2R/c here)
and small-strain (a/R = 0.08-0.11).

The discretisation (one-point tetrahedra graded from h_min at the contact point to 3 mm;
gmsh's size field) errs on the stiff side and the spheres keep some energy in vibration,
so the contact is shorter and the force higher than Hertz's. Measured (contact time,
peak force, against Hertz):

- V = 20 m/s: h_min 0.4 mm (2.4k cells) -12.5 %, +11.6 %; 0.3 mm (9.9k cells) -6.5 %,
  +5.5 %; 0.2 mm (20k cells) -5.7 %, +5.6 %;
- V = 10 m/s: h_min 0.25 mm (12k cells) -5.6 %, +3.6 %; 0.2 mm, 2 mm far (23k cells)
  -4.3 %, +4.3 %.

The loading half follows Hertz's curve to 2-5 %; the unloading is faster, by the energy
the spheres keep in vibration (they rebound at 97.3-98.6 % of their speed). The default
suite runs V = 20 m/s at h_min 0.3 mm (about a minute on a shared machine) with a
discretisation tolerance of 8 % on both; ``--full`` runs V = 10 m/s at 0.2 mm (several
minutes) within the issue's 5 %.
"""

import math

import numpy as np
import pytest
from conftest import run
from test_contact import contact_columns, part_momentum, write_geo

R, E, NU, RHO = 0.01, 200e9, 0.3, 7850.0


def spheres(directory, speed, h_min, h_far, end_time):
    """The two spheres along y, each at ``speed`` (m/s) toward the other, 0.15 h_min apart
    (the gap 0.1 h_min), meshed at h_min (m) within 1.5 mm of the contact point, growing
    at 0.3 to h_far."""
    gap = 0.1 * h_min
    s = 0.75 * gap
    geo = f"""SetFactory("OpenCASCADE");
Sphere(1) = {{0, {-R - s}, 0, {R}}};
Sphere(2) = {{0, {R + s}, 0, {R}}};
Physical Volume("lower") = {{1}};
Physical Volume("upper") = {{2}};
Field[1] = MathEval;
Field[1].F = "min({h_far}, {h_min} + 0.3 * max(0, Sqrt(x^2 + y^2 + z^2) - 0.0015))";
Background Field = 1;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
"""
    return {
        "run": {"end_time": end_time},
        "mesh": {"file": str(write_geo(directory, "spheres.geo", geo))},
        "material": {"model": "linear_elastic", "density": RHO, "young": E, "poisson": NU},
        "part": [
            {"name": "lower", "initial": {"velocity": [0, speed, 0]}},
            {"name": "upper", "initial": {"velocity": [0, -speed, 0]}},
        ],
        "contact": [{"main": ["upper"], "secondary": ["lower"], "gap": gap, "damping": 0.0}],
        "output": {"plot": False},
    }


def part_mass(sim, name) -> float:
    """The mass (kg) of part ``name``'s nodes, summed over the ranks."""
    k = [p.name for p in sim.internal.parts].index(name)
    s = sim.state
    return sim.comm.allreduce(float(s.mass[sim.internal.held[: len(s.mass), k] > 0].sum()))


def hertz(closing_speed):
    """Hertz's contact time (s) and peak force (N) of the two spheres."""
    m = RHO * 4 / 3 * math.pi * R**3
    ms, rs, es = m / 2, R / 2, E / (2 * (1 - NU**2))
    t_c = 2.868 * (ms**2 / (rs * es**2 * closing_speed)) ** 0.2
    approach = (15 * ms * closing_speed**2 / (16 * es * math.sqrt(rs))) ** 0.4
    return t_c, 4 / 3 * es * math.sqrt(rs) * approach**1.5


def test_two_elastic_spheres_collide_as_hertz_says(shared_dir, request):
    """Contact time and peak force within the discretisation tolerance of Hertz's (8 %:
    -6.5 % and +5.5 % measured; --full: 5 %, -4.3 % and +4.3 %), each sphere rebounding
    at 95 % of its speed or more (97 % measured), the momentum kept (to 1e-9: the two
    meshes' masses differ by 0.1 %, so the spheres are not mirror images), the books
    closed."""
    full = request.config.getoption("--full")
    if full:
        speed, h_min, h_far, tolerance = 5.0, 0.2e-3, 2e-3, 0.05
    else:
        speed, h_min, h_far, tolerance = 10.0, 0.3e-3, 3e-3, 0.08
    t_c, peak = hertz(2 * speed)
    sim = run(spheres(shared_dir, speed, h_min, h_far, 1.3 * t_c), shared_dir)
    cc = contact_columns(sim)
    on = np.flatnonzero(cc["normal_force"] > 0)
    duration = cc["time"][on[-1]] - cc["time"][on[0]]
    assert duration == pytest.approx(t_c, rel=tolerance)
    assert np.abs(cc["force_y"]).max() == pytest.approx(peak, rel=tolerance)
    lower, upper = part_momentum(sim, "lower")[1], part_momentum(sim, "upper")[1]
    m_lower, m_upper = part_mass(sim, "lower"), part_mass(sim, "upper")
    assert abs(lower + upper - (m_lower - m_upper) * speed) <= 1e-9 * m_lower * speed
    assert -lower >= 0.95 * m_lower * speed
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12
