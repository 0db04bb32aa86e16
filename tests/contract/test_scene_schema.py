"""What the schema accepts and how it reads it: strict types, the [element] keys, the
refinement and noise rules for built-in bodies, the --set parser."""

import copy
import math

import numpy as np
import pytest
from conftest import bar_scene

from rwall_fem.meshing import rotation_to
from rwall_fem.scene import Element, SceneError, apply_override, parse_scene
from rwall_fem.scene.schema import _own_frame


def _parse(raw):
    return parse_scene(raw, source="s.toml")


def _refused(raw, message):
    with pytest.raises(SceneError, match=message) as err:
        _parse(raw)
    assert "\n" not in str(err.value)


def _with(section, **keys):
    raw = bar_scene(elements=4)
    raw.setdefault(section, {}).update(keys)
    return raw


# --- strict types -------------------------------------------------------------------


@pytest.mark.parametrize("slide, meaning", [(0, "free"), (1, "tied"), (2, "friction")])
def test_slide_takes_the_integers_of_radioss(slide, meaning):
    raw = bar_scene(elements=4)
    raw["wall"][0] |= {"slide": slide} | ({"friction": 0.1} if slide == 2 else {})
    assert _parse(raw).walls[0].slide == meaning


@pytest.mark.parametrize("slide", [1.0, True, "1", [1], 3, -1])
def test_slide_refuses_what_is_not_a_choice(slide):
    raw = bar_scene(elements=4)
    raw["wall"][0]["slide"] = slide
    _refused(raw, r"wall\[0\]\.slide: must be one of 'free', 'tied', 'friction' \(or the")


@pytest.mark.parametrize("plot", [1, 0, "true", 1.0])
def test_plot_is_a_boolean(plot):
    _refused(_with("output", plot=plot), r"output\.plot: must be true or false, got")
    assert _parse(_with("output", plot=False)).output.plot is False


@pytest.mark.parametrize("frames", [1.0, True, -1, 2**63])
def test_integers_are_integers(frames):
    _refused(_with("output", frames=frames), r"output\.frames: must be an integer")


def test_numbers_take_integers_and_refuse_booleans():
    assert _parse(_with("run", end_time=1)).run.end_time == 1.0
    _refused(_with("run", end_time=True), r"run\.end_time: must be a number, got true")


def test_a_quoted_key_stays_on_one_line():
    _refused(_with("run", **{"end\ntime": 1}), r'run\."end\\ntime": unknown key')


def test_seed_takes_the_whole_64_bit_range():
    raw = bar_scene(elements=4)
    raw["mesh"]["noise"] = {"amplitude": 1e-7, "seed": 2**64 - 1}
    assert _parse(raw).mesh.noise == (1e-7, 2**64 - 1)
    raw["mesh"]["noise"]["seed"] = -1
    _refused(raw, r"mesh\.noise\.seed: must be an integer in \[0, 18446744073709551615\]")


# --- [element] ----------------------------------------------------------------------


def test_element_defaults_by_cell_type_and_form():
    """None: decided when the body is built (the cell type, the form and the material)."""
    assert _parse(bar_scene(elements=4)).element == Element(None, None, None)
    assert Element() == Element(None, None, None)
    for form in ("physical", "stiffness", "viscous", "none"):
        element = _parse(_with("element", hourglass=form)).element
        assert element == Element(None, form, None)
    given = _with("element", integration="reduced", hourglass="viscous", hourglass_coefficient=0.3)
    assert _parse(given).element == Element("reduced", "viscous", 0.3)
    full = _parse(_with("element", integration="full")).element
    assert full.integration == "full"


def test_full_integration_of_tetrahedra_is_accepted():
    raw = bar_scene(elements=4, cell="tetrahedron")
    raw["element"] = {"integration": "full"}
    assert _parse(raw).element.integration == "full"


@pytest.mark.parametrize(
    "element, message",
    [
        ({"integration": "full", "hourglass": "physical"}, r"element\.hourglass: needs integra"),
        (
            {"integration": "full", "hourglass_coefficient": 0.1},
            r"element\.hourglass_coefficient: needs integration = 'reduced' \(integration is",
        ),
        (
            {"hourglass": "none", "hourglass_coefficient": 0.1},
            r"element\.hourglass_coefficient: needs hourglass = 'physical', 'stiffness' or",
        ),
        ({"hourglass_coefficient": 0.0}, r"hourglass_coefficient: must be a finite number in \(0,"),
        ({"hourglass_coefficient": math.inf}, r"hourglass_coefficient: must be a finite number"),
        ({"integration": "one_point"}, r"element\.integration: must be one of 'reduced', 'full'"),
        ({"hourglas": "none"}, r"element\.hourglas: unknown key \(did you mean 'hourglass'\?\)"),
    ],
)
def test_bad_element_keys_are_one_line(element, message):
    _refused(bar_scene(elements=4) | {"element": element}, message)


def test_tetrahedra_refuse_reduced_integration_and_hourglass_keys():
    raw = bar_scene(elements=4, cell="tetrahedron")
    _refused(raw | {"element": {"integration": "reduced"}}, r"element\.integration: 'reduced'")
    _refused(raw | {"element": {"hourglass_coefficient": 2.0}}, r"hourglass_coefficient: needs")


# --- refinement and noise of built-in bodies ---------------------------------------------


@pytest.mark.parametrize("axis", [(0, 0, 1), (1, -2, 2), (0, 0, -1), (1, 0, 0), (0.3, 0.1, -1)])
def test_own_frame_is_the_meshing_rotation(axis):
    assert np.allclose(_own_frame(axis), rotation_to(axis).T, atol=1e-14)


def _refined(point, *, axis=(0.0, 0.0, 1.0), shape="bar", radius=None):
    mesh = {"shape": shape, "origin": [0.1, 0.2, 0.3], "axis": list(axis), "element_size": 0.002}
    if shape == "round_bar":
        mesh |= {"radius": 0.005, "length": 0.02}
    else:
        mesh["size"] = [0.01, 0.004, 0.02]
    mesh |= {"refine_point": list(point), "refine_size": 0.001}
    if radius is not None:
        mesh["refine_radius"] = radius
    raw = bar_scene(elements=4)
    raw["mesh"] = mesh
    return raw


def test_a_refine_point_in_reach_of_the_body_is_accepted():
    origin = np.array([0.1, 0.2, 0.3])
    axis = np.array([1.0, -2.0, 2.0]) / 3
    R = rotation_to(axis)
    far_corner = origin + R @ [0.01, 0.004, 0.02]  # the box's corner opposite the origin
    outward = R @ np.array([1.0, 1.0, 1.0]) / math.sqrt(3)
    near, far = far_corner + 0.0079 * outward, far_corner + 0.0081 * outward
    assert _parse(_refined(near, axis=axis)).mesh.refine_radius == pytest.approx(0.008)
    _refused(_refined(far, axis=axis), r"mesh\.refine_point: is 0\.0081 m from the body, fart")
    assert _parse(_refined(far, axis=axis, radius=0.009)).mesh.refine_point == tuple(far)


def test_a_round_bars_box_is_its_radius_about_the_axis():
    inside = [0.1 - 0.005, 0.2, 0.3]  # on the cylinder, at the box's side
    assert _parse(_refined(inside, shape="round_bar")).mesh.shape == "round_bar"
    _refused(
        _refined([0.1 - 0.0131, 0.2, 0.3], shape="round_bar"),
        r"refine_point: is 0\.0081 m .* origin \+ \[-0\.005, 0\.005\] x \[-0\.005, 0\.005\] x",
    )


def test_noise_is_bounded_by_the_smallest_element():
    raw = _refined([0.1, 0.2, 0.3])
    raw["mesh"]["noise"] = {"amplitude": 1e-4}  # 0.1 x refine_size
    assert _parse(raw).mesh.noise == (1e-4, 0)
    raw["mesh"]["noise"] = {"amplitude": 1.01e-4}
    _refused(raw, r"noise\.amplitude: 0\.000101 m is more than 0\.1 x the smallest element size")
    del raw["mesh"]["refine_point"], raw["mesh"]["refine_size"]
    assert _parse(raw).mesh.noise == (1.01e-4, 0)  # element_size alone: up to 2e-4


# --- --set --------------------------------------------------------------------------------


def _override(item, raw=None):
    raw = copy.deepcopy(raw if raw is not None else bar_scene(elements=4))
    apply_override(raw, item, "s.toml")
    return raw


def test_overrides_make_tables_and_read_toml_values():
    assert _override("gravity.acceleration=[0, 0, -9.81]")["gravity"] == {
        "acceleration": [0, 0, -9.81]
    }
    assert _override("wall[0].slide=tied")["wall"][0]["slide"] == "tied"  # a bare word
    assert _override("wall[0].slide=2")["wall"][0]["slide"] == 2
    assert _override("mesh.size[2]=0.05")["mesh"]["size"][2] == 0.05
    assert _override("output.directory = out dir ")["output"]["directory"] == "out dir"
    assert _override("run.end_time=1\nrun.dt=1")["run"]["end_time"] == "1\nrun.dt=1"


@pytest.mark.parametrize(
    "item, message",
    [
        ("wall.0.slide=tied", r"--set wall\.0\.slide: wall is an array: write wall\[0\]"),
        ("wall.slide=tied", r"wall is an array of tables: index it, as in wall\[0\]\.slide"),
        ("run[0]=1", r"--set run\[0\]: run is a table, not an array"),
        ("mesh.cell[0]=1", r"mesh\.cell is a string, not an array"),
        ("output.plot.x=1", r"output\.plot is a boolean, not a table"),
        ("wall[0].point[3]=1", r"index 3 does not exist \(wall\[0\]\.point has 3\)"),
        ("wall[-1].slide=free", r"expected a key path like wall\[0\]\.slide"),
        ("wall[0]]=1", r"expected a key path"),
    ],
)
def test_bad_override_paths_are_one_line(item, message):
    with pytest.raises(SceneError, match=message) as err:
        _override(item)
    assert str(err.value).startswith("s.toml: --set ") and "\n" not in str(err.value)
