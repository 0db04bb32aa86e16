"""Wall geometry: signed distances and normals against hand-computed values."""

import numpy as np
import pytest

from rwall_fem.walls.shapes import CylinderWall, ParallelogramWall, PlaneWall, SphereWall


def test_plane_distance_and_normal():
    plane = PlaneWall([1.0, 0.0, 0.0], [1.0, 0.0, 2.0])  # z normal through x = 1
    x = np.array([[0.0, 0.0, 1.5], [3.0, 2.0, -0.5]])
    assert plane.distance(x) == pytest.approx([1.5, -0.5])
    assert plane.distance(x, offset=np.array([0.0, 0.0, 1.0])) == pytest.approx([0.5, -1.5])
    assert plane.normals(x) == pytest.approx([0.0, 0.0, 1.0])


def test_cylinder_radial_distance_and_axis_node():
    cylinder = CylinderWall([0.0, 0.0, 0.0], [0.0, 0.0, 5.0], diameter=2.0)  # axis z
    x = np.array([[3.0, 4.0, 7.0], [0.0, 0.0, 1.0]])
    assert cylinder.distance(x) == pytest.approx([4.0, -1.0])
    n = cylinder.normals(x)
    assert n[0] == pytest.approx([0.6, 0.8, 0.0])
    # A node on the axis gets a finite unit normal perpendicular to the axis.
    assert np.linalg.norm(n[1]) == pytest.approx(1.0) and n[1][2] == pytest.approx(0.0)


def test_sphere_distance_and_centre_node():
    sphere = SphereWall([1.0, 1.0, 1.0], diameter=4.0)
    x = np.array([[1.0, 1.0, 4.0], [1.0, 1.0, 1.0]])
    assert sphere.distance(x) == pytest.approx([1.0, -2.0])
    n = sphere.normals(x)
    assert n[0] == pytest.approx([0.0, 0.0, 1.0])
    assert np.all(np.isfinite(n)) and np.linalg.norm(n[1]) == pytest.approx(1.0)


def test_parallelogram_patch_and_normal():
    wall = ParallelogramWall([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0])  # sheared
    assert wall.normal == pytest.approx([0.0, 0.0, 1.0])
    x = np.array([[1.5, 0.5, -0.1], [0.2, 0.5, 0.3], [2.6, 0.9, 0.0], [1.0, -0.01, 0.0]])
    assert list(wall.inside_patch(x)) == [True, False, True, False]
    assert wall.distance(x) == pytest.approx([-0.1, 0.3, 0.0, 0.0])


@pytest.mark.parametrize(
    "make",
    [
        lambda: PlaneWall([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]),
        lambda: CylinderWall([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], diameter=0.0),
        lambda: SphereWall([0.0, 0.0, 0.0], diameter=-1.0),
        lambda: ParallelogramWall([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]),
    ],
)
def test_degenerate_shapes_are_refused(make):
    with pytest.raises(ValueError):
        make()
