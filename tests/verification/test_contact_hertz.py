"""Two elastic spheres colliding head-on, against Hertz's theory (issue 30).

Two equal steel spheres (R = 10 mm, E = 200 GPa, nu = 0.3) meet at +-v through a
symmetric, frictionless contact. Hertz (Johnson, Contact Mechanics, 11.4):
with m* = m/2, R* = R/2, E* = E / (2 (1 - nu^2)) and the closing speed V = 2v, the
contact lasts t_c = 2.868 (m*^2 / (R* E*^2 V))^(1/5) and the force peaks at
F = 4/3 E* sqrt(R*) d^(3/2), d = (15 m* V^2 / (16 E* sqrt(R*)))^(2/5) the largest
approach. Hertz is quasi-static (t_c is 10-11 times the spheres' wave transit 2R/c here)
and small-strain (a/R = 0.08-0.11).

The discretisation (one-point tetrahedra graded from h_min at the contact point to h_far;
gmsh's size field) errs on the stiff side and the spheres keep some energy in vibration,
so the contact is shorter and the force higher than Hertz's. The loading half follows
Hertz's curve to 2-5 %; the unloading is faster, by the energy the spheres keep in
vibration (they rebound at 97.3-98.6 % of their speed). Measured (contact time, peak
force, against Hertz):

- whole spheres, undamped: V = 20 m/s: h_min 0.4 mm, 3 mm far (6.5k cells) -7.3 %,
  +6.6 % (-7.4 %, +6.7 % on DOLFINx 0.11, whose mesh is numbered otherwise); 0.3 mm
  (9.9k cells) -6.5 %, +5.5 %; 0.2 mm (20k cells) -5.7 %, +5.6 %; V = 10 m/s: h_min
  0.25 mm (12k cells) -5.6 %, +3.6 %; 0.2 mm, 2 mm far (23k cells) -4.3 %, +4.3 %;
- a quarter of each sphere (cut by the planes x = 0 and z = 0 through the line of
  centres, held there by symmetry conditions: ``docs/theory.md``, "Symmetry planes"),
  with the contact's default damping (0.05: the few nodes in contact of a quarter ring
  more, undamped, and the force's peak with them): V = 20 m/s, h_min 0.3 mm, 3 mm far
  (3.0k cells) -5.4 %, +9.0 % (+5.5 % averaged over t_c / 40); 0.2 mm, 2 mm far (6.4k
  cells) -4.6 %, +7.2 %; V = 10 m/s, 0.2 mm, 2 mm far (6.4k cells) -3.7 %, +4.3 %.

The default suite runs the quarter spheres at V = 10 m/s, h_min 0.2 mm, 2 mm far (as
costly as the whole spheres at 0.3 mm: a quarter of the cells) within the issue's 5 %;
and the whole spheres at V = 20 m/s, h_min 0.4 mm as the check of momentum, symmetry
and rank count, within their discretisation error (8 %). ``--full`` runs the whole
spheres at V = 10 m/s, 0.2 mm, 2 mm far (several minutes) within 5 %.
"""

import math

import numpy as np
import pytest
from conftest import run
from test_contact import contact_columns, part_momentum, write_geo

R, E, NU, RHO = 0.01, 200e9, 0.3, 7850.0


def spheres(directory, speed, h_min, h_far, end_time, quarter=False, damping=0.0):
    """The two spheres along y, each at ``speed`` (m/s) toward the other, 0.15 h_min apart
    (the gap 0.1 h_min), meshed at h_min (m) within 1.5 mm of the contact point, growing
    at 0.3 to h_far; or their quarters x, z >= 0, held on the cut faces x = 0 and z = 0
    by symmetry conditions."""
    gap = 0.1 * h_min
    s = 0.75 * gap
    volumes = """Physical Volume("lower") = {1};
Physical Volume("upper") = {2};"""
    if quarter:
        e = 1e-6
        low = f"{-e}, {-3 * R}, {-e}"  # the boxes' lower corner
        volumes = f"""Box(3) = {{0, {-3 * R}, 0, {2 * R}, {6 * R}, {2 * R}}};
v[] = BooleanIntersection{{ Volume{{1}}; Delete; }}{{ Volume{{3}}; }};
w[] = BooleanIntersection{{ Volume{{2}}; Delete; }}{{ Volume{{3}}; Delete; }};
Physical Volume("lower") = {{v[]}};
Physical Volume("upper") = {{w[]}};
Physical Surface("cut_x") = Surface In BoundingBox{{{low}, {e}, {3 * R}, {2 * R}}};
Physical Surface("cut_z") = Surface In BoundingBox{{{low}, {2 * R}, {3 * R}, {e}}};"""
    geo = f"""SetFactory("OpenCASCADE");
Sphere(1) = {{0, {-R - s}, 0, {R}}};
Sphere(2) = {{0, {R + s}, 0, {R}}};
{volumes}
Field[1] = MathEval;
Field[1].F = "min({h_far}, {h_min} + 0.3 * max(0, Sqrt(x^2 + y^2 + z^2) - 0.0015))";
Background Field = 1;
Mesh.CharacteristicLengthFromPoints = 0;
Mesh.CharacteristicLengthExtendFromBoundary = 0;
Mesh.CharacteristicLengthFromCurvature = 0;
"""
    raw = {
        "run": {"end_time": end_time},
        "mesh": {"file": str(write_geo(directory, "spheres.geo", geo))},
        "material": {"model": "linear_elastic", "density": RHO, "young": E, "poisson": NU},
        "part": [
            {"name": "lower", "initial": {"velocity": [0, speed, 0]}},
            {"name": "upper", "initial": {"velocity": [0, -speed, 0]}},
        ],
        "contact": [{"main": ["upper"], "secondary": ["lower"], "gap": gap, "damping": damping}],
        "output": {"plot": False},
    }
    if quarter:
        raw["boundary"] = [{"group": "cut_x", "components": "x"},
                           {"group": "cut_z", "components": "z"}]  # fmt: skip
    return raw


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


def contact_time_and_peak(sim, share=1.0) -> tuple[float, float]:
    """The contact's duration (s, first to last step with a normal force) and the largest
    force along the line of centres (N) of the whole spheres (``share``: the model's)."""
    cc = contact_columns(sim)
    on = np.flatnonzero(cc["normal_force"] > 0)
    return cc["time"][on[-1]] - cc["time"][on[0]], np.abs(cc["force_y"]).max() / share


def test_two_elastic_spheres_collide_as_hertz_says(shared_dir, request):
    """Whole spheres: contact time and peak force within the discretisation error of
    Hertz's (8 %: -7.3 % and +6.6 % measured at h_min 0.4 mm; --full: 5 %, -4.3 % and
    +4.3 %), each sphere rebounding at 95 % of its speed or more (97 % measured), the
    momentum kept (to 1e-9: the two meshes' masses differ by 0.1 %, so the spheres are not
    mirror images), the books closed; on any number of ranks."""
    full = request.config.getoption("--full")
    if full:
        speed, h_min, h_far, tolerance = 5.0, 0.2e-3, 2e-3, 0.05
    else:
        speed, h_min, h_far, tolerance = 10.0, 0.4e-3, 3e-3, 0.08
    t_c, peak = hertz(2 * speed)
    sim = run(spheres(shared_dir, speed, h_min, h_far, 1.3 * t_c), shared_dir)
    duration, force = contact_time_and_peak(sim)
    assert duration == pytest.approx(t_c, rel=tolerance)
    assert force == pytest.approx(peak, rel=tolerance)
    lower, upper = part_momentum(sim, "lower")[1], part_momentum(sim, "upper")[1]
    m_lower, m_upper = part_mass(sim, "lower"), part_mass(sim, "upper")
    assert abs(lower + upper - (m_lower - m_upper) * speed) <= 1e-9 * m_lower * speed
    assert -lower >= 0.95 * m_lower * speed
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12


def test_quarter_spheres_collide_as_hertz_says_within_5_percent(shared_dir):
    """Quarter spheres (two symmetry planes through the line of centres), V = 10 m/s,
    h_min 0.2 mm, 2 mm far: contact time and peak force within 5 % of Hertz's (-3.7 % and
    +4.8 % measured at the contact's nodal step, +4.3 % at the former global rule's 0.84
    of it: the discretisation's, see above); the spheres rebound (each at 95 %
    of its speed or more), the momentum along the line of centres is kept (1e-9), the
    books close."""
    speed = 5.0
    t_c, peak = hertz(2 * speed)
    raw = spheres(shared_dir, speed, 0.2e-3, 2e-3, 1.15 * t_c, quarter=True, damping=0.05)
    sim = run(raw, shared_dir)
    duration, force = contact_time_and_peak(sim, share=0.25)
    assert duration == pytest.approx(t_c, rel=0.05)
    assert force == pytest.approx(peak, rel=0.05)
    lower, upper = part_momentum(sim, "lower"), part_momentum(sim, "upper")
    m_lower, m_upper = part_mass(sim, "lower"), part_mass(sim, "upper")
    assert abs(lower[1] + upper[1] - (m_lower - m_upper) * speed) <= 1e-9 * m_lower * speed
    assert -lower[1] >= 0.95 * m_lower * speed
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12
