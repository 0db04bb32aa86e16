"""What the frames show, without drawing them: colour ranges and labels, the time label,
the walls as drawn, the camera, the body at true scale."""

import numpy as np
import pytest

from rwall_fem.output.coloring import coloring, round_range
from rwall_fem.output.render import _time_decimals, _time_unit
from rwall_fem.output.view import SLAB, choose_view, wall_surface
from rwall_fem.walls.shapes import CylinderWall, ParallelogramWall, PlaneWall, SphereWall

UP = np.array([0.0, 0.0, 1.0])


def _box(low, high, n=5):
    """Points on a grid in the box [low, high] (m)."""
    axes = [np.linspace(a, b, n) for a, b in zip(low, high, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


@pytest.mark.parametrize(
    "top, signed, expected",
    [
        (11.6, True, (-12.0, 12.0, 5, 0)),  # the bar demo at 10 m/s: -12, -6, 0, 6, 12
        (10.0, True, (-10.0, 10.0, 5, 0)),  # -10, -5, 0, 5, 10
        (1.3, True, (-1.5, 1.5, 7, 1)),  # -1.5, -1, ..., 1.5
        (389.0, False, (0.0, 400.0, 5, 0)),  # 0, 100, ..., 400
        (0.31, False, (0.0, 0.4, 5, 1)),  # 0, 0.1, ..., 0.4
        (9.3, False, (0.0, 10.0, 6, 0)),  # 0, 2, ..., 10
        (0.0, False, (0.0, 1.0, 6, 1)),  # nothing moves: a unit range
    ],
)
def test_round_ranges(top, signed, expected):
    assert round_range(top, signed) == pytest.approx(expected)


@pytest.mark.parametrize("signed", [False, True])
def test_every_round_range_holds_its_top_with_round_labels(signed):
    for top in np.geomspace(1e-7, 1e7, 997):
        low, high, n, decimals = round_range(top, signed)
        assert top <= high < 1.5 * top
        labels = low + (high - low) * np.arange(n) / (n - 1)
        written = [float(f"{v:.{decimals}f}") for v in labels]
        assert np.allclose(written, labels, rtol=0, atol=1e-9 * high)
        assert 3 <= n <= 7


def _frames(values_u, values_v, cells=None):
    frames = []
    for u, v in zip(values_u, values_v, strict=True):
        frame = {"u": u, "v": v, "offsets": np.zeros((1, 3)), "t": 0.0}
        if cells is not None:
            frame["cell_plastic_strain"] = cells
        frames.append(frame)
    return frames


def test_colour_range_of_an_impact_ignores_the_spikes_at_the_wave_front():
    """100 nodes at -10 m/s, then at +10 m/s but 3 of them at 19 m/s: the range is +-10."""
    points = np.zeros((100, 3))
    before, after = np.tile([0, 0, -10.0], (100, 1)), np.tile([0, 0, 10.0], (100, 1))
    after[:3, 2] = 19.0
    frames = _frames([points, points], [before, after])
    paint = coloring("normal_velocity", frames, points, [PlaneWall([0, 0, 0], UP)], UP, 10.0)
    assert paint.clim == (-10.0, 10.0) and paint.cmap == "coolwarm"
    assert paint.title == "velocity along the wall normal (m/s)" and paint.fmt == "%.0f"
    assert np.array_equal(paint.values[1][:4], [19.0, 19.0, 19.0, 10.0])


def test_normal_velocity_on_a_curved_wall_is_along_each_node_normal():
    """Nodes above and beside a cylinder (axis y) moving down at 5 m/s."""
    points = np.array([[0.0, 0.0, 0.02], [0.02, 0.0, 0.0]])
    v = np.tile([0.0, 0.0, -5.0], (2, 1))
    wall = CylinderWall([0, 0, 0], [0, 1, 0], 0.02)
    paint = coloring("normal_velocity", _frames([0 * v], [v]), points, [wall], UP, 5.0)
    assert np.allclose(paint.values[0], [-5.0, 0.0])


def test_displacement_in_micrometres_and_cell_fields_on_cells():
    points = np.zeros((20, 3))
    u = np.zeros((20, 3))
    u[:, 0] = np.linspace(0, 2.86e-4, 20)  # m
    frames = _frames([u], [u], cells=np.array([0.0, 0.0, 0.31]))
    paint = coloring("displacement", frames, points, [], UP, 0.0)
    assert paint.title == "displacement (µm)" and paint.clim == (0.0, 300.0)
    assert paint.cmap == "viridis" and paint.fmt == "%.0f" and not paint.per_cell
    strain = coloring("plastic_strain", frames, points, [], UP, 0.0)
    assert strain.per_cell and strain.title == "equivalent plastic strain"
    assert strain.clim == (0.0, 0.4) and strain.fmt == "%.1f"
    with pytest.raises(ValueError, match="not a field of this body.*no cell fields"):
        coloring("plastic_strain", _frames([u], [u]), points, [], UP, 0.0)


def test_damage_ranges_up_to_failure_at_most():
    """Damage is in [0, 1] (1: failed): a failed cell's damage of 1.13 does not stretch the
    range to 1.2; a damage of at most 0.31 is ranged to 0.4 as any field."""
    points, u = np.zeros((20, 3)), np.zeros((20, 3))
    for largest, top in [(1.13, 1.0), (1.0, 1.0), (0.31, 0.4)]:
        frames = [{"u": u, "v": u, "offsets": np.zeros((0, 3)),
                   "cell_damage": np.array([0.0, 0.2, largest])}]  # fmt: skip
        paint = coloring("damage", frames, points, [], UP, 0.0)
        assert paint.clim == (0.0, top) and paint.title == "damage D"


def test_contact_pressure_ranges_over_the_nodes_in_contact():
    """400 nodes, 40 of them in contact at 1-39 MPa and one at 400 MPa (a rim's spike): the
    range spans the 95th percentile of the nodes in contact (38.05 MPa, to 40), not of all
    nodes (20 MPa: the nodes out of contact would halve it); without stored pressure, one
    line."""
    points, u = np.zeros((400, 3)), np.zeros((400, 3))
    pressure = np.zeros(400)
    pressure[:40] = np.arange(1, 41) * 1e6
    pressure[39] = 400e6
    frames = [{"u": u, "v": u, "offsets": np.zeros((0, 3)), "contact_pressure": pressure}]
    paint = coloring("contact_pressure", frames, points, [], UP, 0.0)
    assert paint.title == "contact pressure (MPa)" and paint.clim == (0.0, 40.0)
    assert paint.cmap == "viridis" and not paint.per_cell
    assert np.allclose(paint.values[0], pressure / 1e6)
    with pytest.raises(ValueError, match="stored no contact pressure"):
        coloring("contact_pressure", _frames([u], [u]), points, [], UP, 0.0)


@pytest.mark.parametrize(
    "end, unit", [(6e-5, "µs"), (3e-3, "ms"), (0.45, "ms"), (2.0, "s"), (0.0, "µs")]
)
def test_time_unit(end, unit):
    assert _time_unit(end)[1] == unit


def test_time_labels_tell_the_frames_apart():
    frames = [{"t": t} for t in np.linspace(0.0, 6e-5, 30)]  # 2.07 us apart
    decimals = _time_decimals(frames, 1e-6)
    labels = {f"{f['t'] / 1e-6:.{decimals}f}" for f in frames}
    assert decimals == 1 and len(labels) == 30


def test_body_at_true_scale():
    """The scene reused for every frame moves the body's points to X + u (m) in place."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    from rwall_fem.output.picture import Picture

    points = _box([0, 0, 0], [1, 1, 1], n=2)
    mesh = {
        "topology": np.array([8, 0, 4, 6, 2, 1, 5, 7, 3]),
        "cell_types": np.array([12], np.uint8),
        "points": points,
    }
    paint = coloring("displacement", _frames([0 * points], [0 * points]), points, [], UP, 0.0)
    view = choose_view(points, [points], [], UP, 4 / 3)
    picture = Picture(mesh, paint, view, (160, 120), erodes=False, cut=None, ghost=False,
                      edges=False)  # fmt: skip
    try:
        for seed in (1, 2):
            u = np.random.default_rng(seed).normal(scale=0.1, size=points.shape)
            image = picture.draw(u, np.linalg.norm(u, axis=1), None, None, "t")
            drawn = vtk_to_numpy(picture.grid.GetPoints().GetData())
            assert np.array_equal(drawn, points + u)
            assert image.shape == (120, 160, 3)
    finally:
        picture.close()


def test_walls_are_drawn_where_the_body_is():
    body = _box([0.0, 0.0, 0.001], [0.01, 0.01, 0.1])
    size = 0.1
    floor = PlaneWall([0, 0, 0], [0, 0, 1])
    slab = wall_surface(floor, np.zeros(3), body, size)
    d = floor.distance(slab.points)
    assert d.max() == pytest.approx(0.0, abs=1e-15) and d.min() == pytest.approx(-SLAB * size)
    assert np.all(slab.points.min(axis=0)[:2] < 0) and np.all(slab.points.max(axis=0)[:2] > 0.01)
    moved = wall_surface(floor, np.array([0, 0, 0.002]), body, size)
    assert floor.distance(moved.points).max() == pytest.approx(0.002)
    cylinder = CylinderWall([0, 0, -0.02], [0, 1, -0.02], 0.02)
    tube = wall_surface(cylinder, np.zeros(3), body, size)
    assert np.allclose(cylinder.distance(tube.points), 0.0, atol=1e-3 * cylinder.radius)
    quads = tube.faces.reshape(-1, 5)
    assert np.all(quads[:, 0] == 4)  # one band of quadrilaterals, open at both ends: an
    edges = np.sort(np.stack([quads[:, 1:], np.roll(quads[:, 1:], -1, axis=1)], -1), -1)
    _, uses = np.unique(edges.reshape(-1, 2), axis=0, return_counts=True)
    assert np.sum(uses == 1) == 2 * 96  # infinite cylinder has no end caps: two free rims
    ends = tube.points @ cylinder.axis
    assert ends.min() < 0.0 and ends.max() > 0.01  # over the body's extent along the axis
    sphere = SphereWall([0, 0, -0.05], 0.02)
    ball = wall_surface(sphere, np.zeros(3), body, size)
    assert np.allclose(sphere.distance(ball.points), 0.0, atol=1e-3 * sphere.radius)


def _fits(view, clouds, aspect):
    """Whether every point of ``clouds`` is in the picture, between the text and the bar."""
    from rwall_fem.output.view import BAND, TIME_CORNER, TOP

    points = np.concatenate(clouds) - view.focal
    right = np.cross(view.up, view.direction)
    x, y = points @ right / view.scale, points @ view.up / view.scale
    corner = (x < -aspect + 2 * aspect * TIME_CORNER[0] / 800) & (y > 1 - 2 * TIME_CORNER[1] / 600)
    return np.all(np.abs(x) <= aspect) and not corner.any() and np.all(
        (y >= 2 * BAND[0] - 1 - 1e-9) & (y <= 2 * TOP - 1 + 1e-9)
    )


def _rod(length, radius, foot=0.0, n=40):
    """Points (m) of the surface of a rod along z from 0 to ``length`` whose radius
    swells to ``foot`` (m) at z = 0 over its first fifth (a Taylor rod's mushroom)."""
    z, angle = np.meshgrid(np.linspace(0, length, n), np.linspace(0, 2 * np.pi, n))
    r = radius + max(foot - radius, 0.0) * np.clip(1 - z / (0.2 * length), 0, 1) ** 2
    return np.column_stack([(r * np.cos(angle)).ravel(), (r * np.sin(angle)).ravel(), z.ravel()])


@pytest.mark.parametrize("cut", [None, [1.0, 0.0, 0.0]])
def test_a_taylor_rods_last_frame_fills_half_of_the_picture(cut):
    """A copper rod 32.4 mm long that ends 21.5 mm long with a foot 7.15 mm in radius (the
    Taylor demo), seen in one view for every frame: the last frame is more than half of
    the picture's height (it is beside the time's corner, not under it), and every frame
    is in the picture."""
    first, last = _rod(32.4e-3, 3.2e-3), _rod(21.5e-3, 3.2e-3, foot=7.15e-3)
    walls = [PlaneWall([0, 0, 0], [0, 0, 1])]
    view = choose_view(first, [first, last], walls, UP, 4 / 3, cut_normal=cut)
    assert np.ptp(last @ view.up) / (2 * view.scale) > 0.5
    assert _fits(view, [first, last], 4 / 3)


def test_camera_between_a_floor_and_a_press_looks_level():
    """A bar between a floor (normal up) and a press (normal down): the camera can see
    both from their allowed sides only from the horizon."""
    body = _box([0, 0, 0], [0.01, 0.01, 0.1])
    walls = [PlaneWall([0, 0, 0], [0, 0, 1]), PlaneWall([0, 0, 0.1], [0, 0, 0])]
    view = choose_view(body, [body], walls, UP, 4 / 3)
    assert view.direction @ UP == pytest.approx(0.0, abs=1e-12)
    assert all(view.behind(w) for w in walls)
    assert _fits(view, [body], 4 / 3)


def test_camera_over_a_floor_looks_down_and_fills_the_picture():
    body = _box([0, 0, 0], [0.01, 0.01, 0.1])
    floor = PlaneWall([0, 0, 0], [0, 0, 1])
    view = choose_view(body, [body], [floor], UP, 4 / 3)
    assert view.direction @ UP == pytest.approx(np.sin(np.radians(20)))
    assert view.behind(floor) and not view.behind(SphereWall([0, 0, 0], 0.01))
    assert _fits(view, [body], 4 / 3)
    assert 2 * view.scale < 1.2 * 0.1 / 0.74  # the bar's height fills the band


def test_camera_of_a_plate_looks_from_higher_up():
    plate = _box([-0.03, -0.03, 0.015], [0.03, 0.03, 0.018])
    view = choose_view(plate, [plate], [SphereWall([0, 0, 0], 0.03)], UP, 4 / 3)
    assert view.direction @ UP == pytest.approx(np.sin(np.radians(30)))


def test_camera_beside_a_finite_wall_looks_along_its_edge():
    """A bar standing over the edge x = 0.04 of a parallelogram, tipping in x: the camera
    looks along y, the edge, so that the overhang and the tipping show in full."""
    body = np.vstack([_box([0.035, -0.005, 0], [0.045, 0.005, 0.06]), [[0.07, 0, 0.06]]])
    wall = ParallelogramWall([0, -0.02, 0], [0.04, -0.02, 0], [0, 0.02, 0])
    view = choose_view(body[:-1], [body], [wall], UP, 4 / 3)
    assert view.direction[0] == pytest.approx(0.0, abs=1e-12) and view.direction[1] < 0
    assert view.behind(wall)


@pytest.mark.parametrize("name", ["viridis", "coolwarm"])
def test_colour_maps_are_matplotlibs(name):
    """The renderer's colour maps (65 colours each, interpolated) are matplotlib's to 5 of
    255 levels, without importing it."""
    import matplotlib

    from rwall_fem.output.coloring import colour_table

    theirs = matplotlib.colormaps[name](np.linspace(0.0, 1.0, 256))[:, :3]
    assert np.abs(colour_table(name, 256) - theirs).max() < 5 / 255
