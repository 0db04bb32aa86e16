"""The reference page and the JSON Schema come from the schema, are up to date, ship with
the package, and agree with the validator on the demos, the test scenes and the bad scenes."""

import importlib.resources
import json
import tomllib
from pathlib import Path

import jsonschema
import pytest
from conftest import SCENE, bar_scene, block_scene

from rwall_fem.scene.keys import Each, Real, Sub, Vector, keys_of
from rwall_fem.scene.reference import PAGE, SCHEMA_FILE, json_schema, reference_page, tables

ROOT = Path(__file__).resolve().parents[2]
DEMOS = sorted((ROOT / "demos").glob("*.toml"))
BAD = sorted((ROOT / "tests" / "bad_scenes").glob("*.toml"))
VALIDATOR = jsonschema.Draft202012Validator(json_schema())
REGENERATE = "run `python -m rwall_fem.scene.reference`"


def test_the_reference_page_is_up_to_date():
    assert (ROOT / PAGE).read_text() == reference_page(), REGENERATE


def test_the_json_schema_is_up_to_date_and_valid():
    assert json.loads(SCHEMA_FILE.read_text()) == json_schema(), REGENERATE
    jsonschema.Draft202012Validator.check_schema(json_schema())


def test_the_package_holds_the_json_schema():
    shipped = importlib.resources.files("rwall_fem.scene").joinpath("scene.schema.json")
    assert json.loads(shipped.read_text()) == json_schema()
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "scene.schema.json" in pyproject["tool"]["setuptools"]["package-data"]["rwall_fem.scene"]


def test_every_key_carries_a_doc_and_numbers_a_unit():
    dimensionless = {
        "dt_scale", "max_energy_error", "poisson", "hourglass_coefficient", "axis", "friction",
        "coefficient", "steps", "hardening_exponent", "strain_rate_coefficient",
        "softening_exponent", "taylor_quinney", "max_added_mass", "plastic_strain",
        "d1", "d2", "d3", "d4", "d5", "hourglass_coefficients", "shear_factor", "zoom",
        "stiffness_scale", "damping", "failed_share", "hourglass_stiffness", "drilling_stiffness",
        "gap_scale", "gap_size_share",
    }  # fmt: skip
    for where, _, cls in tables():
        assert cls.__table__.doc, where
        for name, (_, k) in keys_of(cls).items():
            assert k.doc and "\n" not in k.doc, f"{where}.{name}"
            if isinstance(k.type, (Real, Vector)) and name not in dimensionless:
                assert k.unit, f"{where}.{name} has no unit"
            if not isinstance(k.type, (Sub, Each)):
                assert k.type.type_text, f"{where}.{name}"


@pytest.mark.parametrize("path", DEMOS, ids=[p.stem for p in DEMOS])
def test_the_demos_validate_against_the_json_schema(path):
    VALIDATOR.validate(tomllib.loads(path.read_text()))


@pytest.mark.parametrize(
    "raw",
    [
        tomllib.loads(SCENE),
        bar_scene(),
        bar_scene(cell="tetrahedron", axis=(1.0, -2.0, 2.0), wall=False),
        block_scene(gravity=(0, 0, -9.81), wall=[{"kind": "sphere", "point": [0, 0, 0],
                                                  "diameter": 1.0, "slide": 2, "friction": 0.1}]),
    ],
    ids=["SCENE", "bar", "tetrahedra", "block"],
)  # fmt: skip
def test_the_test_scenes_validate_against_the_json_schema(raw):
    VALIDATOR.validate(json.loads(json.dumps(raw)))


# The bad scenes whose mistake is beyond a JSON Schema: a number compared with the stable
# step, a file or node set looked up, points or values compared across keys or rows (a
# table's increasing strains, melting above room temperature); and JSON's numbers, where
# 1.0 is the integer 1 and a 400-digit integer is a number like any other.
BEYOND = {
    "09_dt_above_limit",
    "40_wall_slide_float",
    "42_end_time_400_digits",
    "18_mesh_file_missing",
    "26_wall_degenerate_normal",
    "30_wall_unknown_group",
    "32_boundary_unknown_group",
    "44_refine_point_far_from_the_body",
    "45_noise_amplitude_not_small",
    "56_hardening_curve_decreasing_strain",
    "60_melting_below_room",
    # What only the mesh file, the size estimates or the file system can tell.
    "62_mesh_file_geo_syntax_error",
    "63_mesh_file_garbage",
    "64_mesh_file_empty",
    "65_density_1e-300",
    "66_output_directory_is_a_file",
    "67_output_directory_unwritable",
    "68_element_size_1e-7",
    "69_cube_at_1_mm",
    "70_plate_layers_100000",
    "71_refine_size_1e-9",
    "72_end_time_1e9",
    "73_frames_1e8",
    "74_wall_secondary_all_excluded",
    "75_mesh_file_noise_not_small",
    "76_mesh_file_above_max_cells",
    "81_dt_min_above_the_step_at_rest",
    "100_hourglass_on_a_tetrahedral_mesh_file",
    "101_hourglass_coefficient_on_a_tetrahedral_mesh_file",
    "102_reduced_on_a_tetrahedral_mesh_file",
    "104_wall_points_overflow",
    "207_erode_below_a_dt_min_above_the_step",
    "208_damage_colour_without_failure",  # the cell fields are the body's
    "334_contact_pressure_colour_without_contact",  # the contacts are the scene's tables
    "220_erode_below_a_dt_min_above_the_step_of_one_part",
    "221_mass_scaling_that_would_add_the_body_mass_at_rest",
    "222_mesh_file_with_the_same_cells_in_two_regions",
    "223_mesh_file_with_a_flat_cell",
    "210_output_units_unknown",  # a unit system's codes and sizes are read by rwall_fem.units
    "211_output_units_deck_of_a_toml_scene",
    "242_view_cut_misses_the_body",  # the body's nodes
    "245_view_range_upside_down",  # low < high: two items of an array
    "246_view_focus_unknown_part",  # the parts of [[part]]
    # The parts: what the mesh's regions tell, and what ties keys of several tables.
    "84_part_unknown_region",
    "85_part_region_left_out",
    "86_part_name_twice",
    "87_part_region_twice",
    "88_parts_bonded_at_different_speeds",
    "90_secondary_parts_unknown",
    "91_front_length_of_the_whole_bar",
    "94_part_without_cells",
    "300_contact_unknown_part",  # the parts are the body's
    "302_contact_gap_larger_than_the_parts",
    "306_contact_shell_gap_larger_than_the_tube",
    "95_part_density_1e-300",
    # Loads: what the mesh's groups and ordered rows tell, and keys tied together.
    "251_load_history_decreasing",
    "252_load_unknown_group",
    "254_damping_both_zero",
    # Rigid bodies: their nodes, masses and inertia are the mesh's; a box compares corners.
    "265_rigid_body_box_without_nodes",
    "266_rigid_body_node_in_two_bodies",
    "267_rigid_body_zero_mass",
    "268_rigid_body_unknown_set",
    "270_rigid_body_with_mass_scaling",
    "271_rigid_body_nodes_on_a_line",
    "272_rigid_body_clamped",
    "273_rigid_body_box_inverted",
    # Shells: which cells a key fits ties [mesh] to [element] and the parts' (and a mesh
    # file's cells are known once it is read); a tube's trigger ties its keys together.
    "282_shell_triangle_formulation_on_quadrilaterals",
    "283_shell_quadrilateral_formulation_on_triangles",
    "286_shell_thickness_on_hexahedra",
    "287_solid_integration_on_shells",
    "288_shell_cell_on_a_bar",
    "289_shell_plate_with_layers",
    "290_shell_thickness_on_a_volume_mesh_file",
    "291_shell_mesh_file_without_thickness",
    "293_tube_of_hexahedra",
    "294_tube_trigger_without_wavelength",
    "295_tube_trigger_longer_than_the_tube",
    "296_rotations_held_on_a_solid",
    "297_shells_beside_solids_in_one_mesh_file",
    "298_shell_pressure_on_an_edge",
    "299_shell_stiffness_damping",
    "332_shell_drilling_stiffness_on_triangles",
    "333_shell_drilling_stiffness_on_hexahedra",
    "354_contact_gap_max_on_solids",  # a key of shells' gap on a body of solids
    # The flow-stress cap lies above the initial yield stress: two values compared.
    "320_flow_stress_cap_below_yield",
    "322_johnson_cook_cap_below_yield",
    "308_piece_name_twice",  # the pieces' names and cells are compared across tables
    "309_piece_cells_differ",
    "352_contact_stiffness_bounds_crossed",  # two values compared
}


def test_the_json_schema_refuses_the_bad_scenes_it_can_see():
    refused, accepted = set(), set()
    for path in BAD:
        try:
            raw = tomllib.loads(path.read_bytes().decode())
        except (UnicodeDecodeError, tomllib.TOMLDecodeError, ValueError, RecursionError):
            continue  # not TOML at all
        (refused if any(VALIDATOR.iter_errors(raw)) else accepted).add(path.stem)
    assert accepted == BEYOND
    assert len(refused) >= 35
