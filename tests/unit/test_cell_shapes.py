"""Flat and inside-out cells (:mod:`rwall_fem.cell_shapes`), against closed forms: a cube
of edge h has h^3 at every corner (the determinant of its three edges there), a cube
with one corner pushed in by s h along each axis (1 - 3 s) h^3 at that corner (the
determinant of I - s ones), a sheared cube h^3 everywhere, a cube whose top face lies on
its bottom face 0 everywhere; a tetrahedron six times its volume."""

import numpy as np
import pytest

from rwall_fem.cell_shapes import bad_cells, corner_volumes

H = 0.002
CUBE = H * np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                     [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)  # fmt: skip


def test_corner_volumes_of_a_cube_a_pushed_corner_and_a_shear():
    assert corner_volumes(CUBE[None]) == pytest.approx(np.full((1, 8), H**3), rel=1e-12)
    for s in (0.2, 0.6):
        pushed = CUBE.copy()
        pushed[0] += s * H
        assert corner_volumes(pushed[None])[0, 0] == pytest.approx((1 - 3 * s) * H**3)
    sheared = CUBE.copy()
    sheared[4:, 0] += 0.7 * H
    assert corner_volumes(sheared[None]) == pytest.approx(np.full((1, 8), H**3), rel=1e-12)
    tet = CUBE[[0, 1, 3, 4]]
    assert corner_volumes(tet[None])[0, 0] == pytest.approx(H**3)  # 6 x H^3 / 6


def test_flat_and_inside_out_cells_are_found_and_mirrored_ones_are_not():
    mirrored = CUBE[[1, 0, 3, 2, 5, 4, 7, 6]]
    flat = CUBE.copy()
    flat[4:, 2] = 0.0
    pushed = CUBE.copy()
    pushed[0] += 0.6 * H  # through the plane of its three neighbours
    tiny = CUBE * 1e-6  # a valid cell of a micrometre: the test is relative to its size
    bad, corner = bad_cells(np.array([CUBE, mirrored, flat, pushed, tiny]))
    assert bad.tolist() == [2, 3] and corner[1] == 0
    flat_tet = CUBE[[0, 1, 3, 2]]  # four nodes of one face
    assert bad_cells(np.array([CUBE[[0, 1, 3, 4]], flat_tet]))[0].tolist() == [1]
    assert bad_cells(np.zeros((0, 8, 3)))[0].tolist() == []
