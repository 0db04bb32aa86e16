"""Hostile input: whatever a scene file or a ``--set`` holds, the answer is a scene or one
line naming the file and the key, never a traceback (exit code 2 from the command line)."""

import codecs
import copy
import datetime
import itertools
import math
import random

import pytest
from conftest import SCENE
from mpi4py import MPI

from rwall_fem.cli import main
from rwall_fem.scene import Scene, SceneError, apply_override, load_scene, parse_scene
from rwall_fem.scene.keys import Each, Sub, keys_of
from rwall_fem.scene.reference import tables

# A scene that opens every table: each key below is set in a context where it is allowed.
FULL = {
    "run": {"end_time": 1e-5, "dt": 1e-8},
    "mesh": {
        "shape": "plate_with_hole",
        "size": [0.06, 0.06, 0.004],
        "hole_radius": 0.006,
        "element_size": 0.003,
        "refine_point": [0.0, 0.0, 0.0],
        "refine_size": 0.0015,
        "noise": {"amplitude": 1e-7, "seed": 7},
    },
    "material": {
        "model": "johnson_cook",
        "density": 8960.0,
        "young": 124e9,
        "poisson": 0.34,
        "yield_stress": 90e6,
        "hardening_coefficient": 292e6,
        "hardening_exponent": 0.31,
        "strain_rate_coefficient": 0.025,
        "reference_strain_rate": 1.0,
        "heating": {
            "softening_exponent": 1.09,
            "melting_temperature": 1356.0,
            "specific_heat": 383.0,
            "room_temperature": 294.0,
            "taylor_quinney": 0.9,
        },
    },  # fmt: skip
    "element": {"integration": "reduced", "hourglass": "viscous"},
    "initial": {"velocity": [0.0, 0.0, -1.0]},
    "gravity": {"acceleration": [0.0, 0.0, -9.81]},
    "boundary": [{"group": "sides", "velocity": [[0, 0, 0, 0], [1, 0, 0, 1]]}],
    "load": [{"kind": "force", "group": "top", "force": [0, 0, 1], "per": "set",
              "history": [[0, 0], [1e-5, 1]]}],
    "added_mass": [{"group": "top", "mass": 1e-3, "per": "set"}],
    "damping": {"alpha": 10.0, "beta": 1e-9, "group": "top"},
    "wall": [
        {
            "kind": "cylinder",
            "point": [0.0, 0.0, 0.01],
            "axis_point": [0.0, 1.0, 0.01],
            "diameter": 0.01,
            "slide": "friction",
            "friction": 0.1,
            "friction_filter": {"steps": 10},
            "secondary": {"search_distance": 0.001},
            "motion": {"mass": 1.0, "velocity": [0.0, 0.0, -1.0]},
        }
    ],
    "rigid_body": [
        {
            "sets": ["hole"],
            "parts": ["body"],
            "box": {"low": [-0.03, -0.03, 0.0], "high": [-0.02, -0.02, 0.004]},
            "main_node": [0.0, 0.0, 0.01],
            "mass": 0.1,
            "inertia": [1e-5, 1e-5, 1e-5, 0.0, 0.0, 0.0],
            "center": "nodes",
            "node_masses": True,
            "angular_velocity": [0.0, 0.0, 1.0],
        }
    ],
    "output": {"frames": 1, "view": {"cut": "x"}},
}

# The same with the other mesh shapes and wall kinds, so that every key is somewhere allowed.
FAILING = {
    "model": "elastic_plastic", "density": 8930.0, "young": 117e9, "poisson": 0.35,
    "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e8,
    "failure": {"criterion": "johnson_cook", "d1": 0.05, "d2": 0.5, "d3": -1.5},
}  # fmt: skip
OTHERS = [
    FULL | {"load": [{"kind": "pressure", "group": "top", "pressure": 1e5}]},
    FULL
    | {
        "contact": [
            {
                "main": ["body"], "self": True, "symmetric": True, "gap": 1e-4,
                "stiffness_scale": 1.0, "damping": 0.05, "friction": 0.2,
                "friction_filter": {"coefficient": 0.5},
            }
        ]
    },  # fmt: skip
    FULL
    | {
        "mesh": {"shape": "round_bar", "radius": 0.01, "length": 0.1, "element_size": 0.01},
        "material": {
            "model": "elastic_plastic",
            "density": 8930.0,
            "young": 117e9,
            "poisson": 0.35,
            "hardening": "power",
            "yield_stress": 400e6,
            "hardening_coefficient": 1e8,
            "hardening_exponent": 0.5,
        },  # fmt: skip
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1], "slide": 1}],
    },
    FULL
    | {
        "material": {
            "model": "elastic_plastic",
            "density": 8930.0,
            "young": 117e9,
            "poisson": 0.35,
            "hardening": "linear",
            "yield_stress": 400e6,
            "hardening_modulus": 1e8,
        },  # fmt: skip
    },
    FULL
    | {
        "material": {
            "model": "elastic_plastic",
            "density": 8930.0,
            "young": 117e9,
            "poisson": 0.35,
            "hardening": "table",
            "hardening_curve": [[0.0, 400e6], [1.0, 500e6]],
        },  # fmt: skip
    },
    FULL | {"material": FAILING, "part": [{"name": "body", "material": FAILING}]},
    FULL
    | {
        "mesh": {"file": "part.msh", "noise": {"amplitude": 1e-7}},
        "wall": [
            {"kind": "sphere", "point": [0, 0, 0], "diameter": 1.0},
            {
                "kind": "parallelogram",
                "point": [0, 0, 0],
                "corner1": [1, 0, 0],
                "corner2": [0, 1, 0],
            },
        ],
    },
    FULL
    | {
        "mesh": {
            "shape": "round_bar",
            "radius": 0.01,
            "length": 0.1,
            "element_size": 0.01,
            "front_length": 0.02,
        },
        "part": [
            {
                "name": "nose",
                "volumes": ["front"],
                "material": FULL["material"],
                "element": {"integration": "full"},
                "initial": {"velocity": [0.0, 0.0, -1.0]},
            },
            {"name": "body"},
        ],
        "wall": [
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal_point": [0, 0, 1],
                "secondary": {"parts": ["nose"]},
            }
        ],
    },
]

# [[piece]] instead of [mesh]: FULL's shape as the body's one piece.
OTHERS.append(
    {k: v for k, v in FULL.items() if k != "mesh"}
    | {"piece": [{"name": "body", **{k: v for k, v in FULL["mesh"].items() if k != "noise"}}]}
)

# A value of every TOML type, and the awkward ones of each.
VALUES = [
    "text",
    "",
    "x" * 500,
    "line\nbreak",
    0,
    1,
    -1,
    2,
    10**400,
    -(10**400),
    2**64,
    0.0,
    1.0,
    -1e-300,
    1e308,
    math.nan,
    math.inf,
    -math.inf,
    True,
    False,
    [],
    [1, 2, 3],
    [1.0, 2.0],
    [[0, 0, 0, 0]],
    [[1, 2], [3]],
    ["a", "b"],
    [True, False, True],
    [math.nan, 0, 0],
    [[[[]]]],
    {},
    {"a": 1},
    {"x\ny": {"z": []}},
    datetime.datetime(1979, 5, 27, 7, 32, tzinfo=datetime.UTC),
    datetime.date(1979, 5, 27),
    datetime.time(7, 32),
]


def _key_paths():
    """Every (table path, key) of the schema; ``wall``/``boundary`` tables are element 0."""
    for where, _, cls in tables():
        for name in keys_of(cls):
            yield tuple(p for p in where.split(".") if p), name


def _set(raw, where, name, value):
    node = raw
    for part in where:
        node = node[part][0] if isinstance(node[part], list) else node[part]
    node[name] = value


def _has(raw, where) -> bool:
    """Whether ``raw`` has the table at the path ``where``."""
    try:
        _set(copy.deepcopy(raw), where, "probe", 1)
    except KeyError:
        return False
    return True


def _one_line_or_scene(raw, source="fuzz.toml"):
    try:
        parse_scene(raw, source=source)
    except SceneError as err:
        message = str(err)
        assert "\n" not in message and message.startswith(f"{source}: "), message
        assert len(message) < 600, message


def test_full_scene_is_valid():
    scene = parse_scene(copy.deepcopy(FULL))
    assert scene.walls[0].motion.mass == 1.0 and scene.element.hourglass_coefficient is None


@pytest.mark.parametrize("where, name", list(_key_paths()), ids=".".join)
def test_every_key_with_every_type_gives_a_scene_or_one_line(where, name):
    for base, value in itertools.product([FULL, *OTHERS], VALUES):
        raw = copy.deepcopy(base)
        try:
            _set(raw, where, name, copy.deepcopy(value))
        except KeyError:  # a table this base does not have
            continue
        _one_line_or_scene(raw)


@pytest.mark.parametrize("name", list(keys_of(Scene)))
def test_every_table_replaced_by_every_type(name):
    for value in VALUES:
        _one_line_or_scene(copy.deepcopy(FULL) | {name: copy.deepcopy(value)})
    for value in VALUES:  # and inside the arrays of tables
        raw = copy.deepcopy(FULL)
        if isinstance(raw.get(name), list):
            raw[name] = [copy.deepcopy(value)]
            _one_line_or_scene(raw)


def test_unknown_keys_of_every_kind_give_one_line():
    for where, _, _ in tables():
        path = [p for p in where.split(".") if p]
        base = next(b for b in [FULL, *OTHERS] if _has(b, path))
        for name in ("", " ", "x\ny", '"', "ĳ", "a.b", "[0]", "0" * 300):
            raw = copy.deepcopy(base)
            _set(raw, path, name, 1)
            with pytest.raises(SceneError, match="unknown key") as err:
                parse_scene(raw, source="fuzz.toml")
            assert "\n" not in str(err.value)


def test_not_a_table_at_the_top():
    for value in VALUES:
        if not isinstance(value, dict):
            with pytest.raises(SceneError, match=r"^api: must be a table"):
                parse_scene(value, source="api")


def test_cut_and_shuffled_scene_files(tmp_path):
    """Every prefix of a scene file, and files of random bytes: a scene or one line."""
    source = SCENE.encode()
    rng = random.Random(1)
    samples = [source[:n] for n in range(0, len(source), 7)]
    samples += [bytes(rng.randrange(256) for _ in range(rng.randrange(1, 200))) for _ in range(50)]
    samples += [bytes(rng.choice(b"[]{}=.,\"'#\n \t0aZ") for _ in range(80)) for _ in range(200)]
    path = tmp_path / f"cut{MPI.COMM_WORLD.rank}.toml"
    for data in samples:
        path.write_bytes(data)
        try:
            load_scene(path)
        except SceneError as err:
            assert "\n" not in str(err) and str(err).startswith(f"{path}: "), str(err)


def test_a_byte_order_mark_is_accepted(tmp_path):
    plain, marked = tmp_path / f"plain{MPI.COMM_WORLD.rank}.toml", tmp_path / "bom.toml"
    plain.write_text(SCENE)
    marked.write_bytes(codecs.BOM_UTF8 + SCENE.encode())
    assert load_scene(marked).walls == load_scene(plain).walls


def test_a_scene_that_is_not_utf8_is_one_line(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(SCENE.replace("[output]", "# r\xe9sum\xe9\n[output]").encode("latin-1"))
    with pytest.raises(SceneError, match=r"latin1\.toml: not a text file \(binary data at byte"):
        load_scene(path)


# --- --set -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "item, message",
    [
        ("run.end_time.foo=1", "--set run.end_time.foo: run.end_time is a number, not a table"),
        ("mesh.size[0].x=1", "--set mesh.size[0].x: mesh.size[0] is a number, not a table"),
        ("wall.0.slide=tied", "--set wall.0.slide: wall is an array: write wall[0]"),
        ("wall[0].slide={a=1}", "wall[0].slide: must be one of 'free', 'tied', 'friction'"),
        ("wall[0].slide=1.0", "wall[0].slide: must be one of 'free', 'tied', 'friction'"),
        ("wall[3].slide=free", "--set wall[3].slide: index 3 does not exist (wall has 1)"),
        ("wall[0]x=1", "--set wall[0]x: expected a key path like wall[0].slide"),
        ("run..end_time=1", "--set run..end_time: expected a key path"),
        ("=1", "--set '=1': expected key.path=value"),
        ("run.end_time", "--set 'run.end_time': expected key.path=value"),
        ("output.plot=1", "output.plot: must be true or false, got 1"),
        ("run.end_time=" + "9" * 400, "run.end_time: must be a finite number in (0, inf), got a"),
        ("mesh.noise={amplitude=1e-7, seed=18446744073709551616}", "mesh.noise.seed: must be"),
    ],
)
def test_bad_overrides_are_one_line_with_exit_code_2(item, message, shared_dir, capsys):
    path = f"{shared_dir}/scene.toml"
    if MPI.COMM_WORLD.rank == 0:
        open(path, "w").write(SCENE)
    MPI.COMM_WORLD.barrier()
    code = main(["check", path, "--set", item])
    err = capsys.readouterr().err
    assert code == 2
    if MPI.COMM_WORLD.rank == 0:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"rwall-fem: error: {path}: "), err
        assert message in lines[0], err


def test_random_override_keys_give_one_line():
    rng = random.Random(2)
    alphabet = "ab0.[]=_-\n x"
    raw = {"run": {"end_time": 1.0}, "wall": [{"kind": "plane"}], "mesh": {"size": [1, 2, 3]}}
    words = ["run", "end_time", "wall", "mesh", "size", "[0]", "[1]", ".", "kind", "x"]
    items = ["".join(rng.choice(alphabet) for _ in range(rng.randrange(1, 12))) for _ in range(300)]
    items += ["".join(p) + "=1" for p in itertools.product(words, repeat=3)]
    for item in items:
        try:
            apply_override(copy.deepcopy(raw), item, "s.toml")
        except SceneError as err:
            assert "\n" not in str(err) and str(err).startswith("s.toml: --set "), str(err)


def test_every_table_type_is_reachable():
    """The fuzzing above reaches every table: a Sub or Each key opens each of them."""
    opened = {
        k.type.cls
        for _, _, cls in tables()
        for _, k in keys_of(cls).values()
        if isinstance(k.type, (Sub, Each))
    }
    assert len(opened) == len({cls for _, _, cls in tables()}) - 1
