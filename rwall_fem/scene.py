"""Scenes: a TOML file read into validated dataclasses.

A scene is checked whole before anything heavy starts. Every problem is a
:class:`SceneError` whose message is one line naming the file, the key path
(``wall[0].normal_point``) and what is allowed. Nothing downstream of this
module reads the raw TOML.
"""

from __future__ import annotations

import difflib
import itertools
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "Initial",
    "Material",
    "MeshSpec",
    "Output",
    "RunSettings",
    "Scene",
    "SceneError",
    "WallSpec",
    "apply_override",
    "load_scene",
    "parse_scene",
]

MESH_DIR = Path(__file__).resolve().parent.parent / "meshes"
# Small strain (constant stiffness), and the large-deformation (hyperelastic) models.
MATERIAL_MODELS = ("linear_elastic", "saint_venant_kirchhoff", "neo_hookean")


class SceneError(ValueError):
    """A scene that cannot run; the message is one line meant for the user."""


@dataclass(frozen=True)
class RunSettings:
    end_time: float  # s
    dt_scale: float = 0.9  # fraction of the stable step 2/omega_max
    dt: float | None = None  # s, a fixed step; refused above the stable limit
    max_energy_error: float = 0.05  # the run stops when |energy balance error| exceeds this
    min_dt: float = 0.0  # s: the run stops when the step falls below this


@dataclass(frozen=True)
class MeshSpec:
    shape: str | None  # one of MESH_SHAPES, or None when ``file`` is given
    file: Path | None = None
    # m: lowest corner (bar, plates), centre of the bottom face (round bar); before turning
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size: tuple[float, float, float] = (0.01, 0.01, 0.1)  # m, along the body's own x, y, z
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)  # direction of the body's own z
    element_size: float = 2e-3  # m
    cell: str = "hexahedron"
    noise: tuple[float, int] | None = None  # (amplitude in m, seed) on initial coordinates
    radius: float | None = None  # m, round bar
    length: float | None = None  # m, round bar, along its own z
    layers: int = 0  # plates: elements through the thickness; 0: the fewest <= element_size
    hole_radius: float | None = None  # m, plate with a hole
    hole_offset: tuple[float, float] = (0.0, 0.0)  # m, hole centre - plate centre (own x, y)
    refine_point: tuple[float, float, float] | None = None  # m, scene coordinates
    refine_size: float | None = None  # m, element size at refine_point
    refine_radius: float | None = None  # m, over which the size grows back to element_size


@dataclass(frozen=True)
class Material:
    model: str
    density: float  # kg/m^3
    young: float  # Pa
    poisson: float

    @property
    def lame(self) -> tuple[float, float]:
        """Lamé parameters (lambda, mu) in Pa."""
        E, nu = self.young, self.poisson
        return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))

    @property
    def p_wave_speed(self) -> float:
        """Dilatational wave speed sqrt((lambda + 2 mu)/rho) in m/s."""
        lmbda, mu = self.lame
        return math.sqrt((lmbda + 2 * mu) / self.density)


@dataclass(frozen=True)
class Initial:
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)  # m/s


@dataclass(frozen=True)
class Secondary:
    """Which nodes a wall acts on; the default is every boundary node of the body."""

    search_distance: float | None = None  # m: nodes with 0 <= d <= this at the start
    add: tuple[str, ...] = ()  # named node sets (gmsh physical groups) to include
    exclude: tuple[str, ...] = ()  # named node sets to leave out; exclusion wins


@dataclass(frozen=True)
class Motion:
    """A main node of ``mass`` starting at ``velocity``, or a prescribed ``velocity`` history."""

    mass: float | None  # kg; None for a prescribed motion
    velocity: tuple  # m/s: [vx, vy, vz], or rows (t, vx, vy, vz) for a prescribed history

    @property
    def prescribed(self) -> bool:
        return self.mass is None


@dataclass(frozen=True)
class WallSpec:
    kind: str  # "plane", "cylinder", "sphere", "parallelogram"
    point: tuple[float, float, float]  # M (m): on the plane, the axis, the centre, a corner
    normal_point: tuple[float, float, float] | None = None  # plane: M1, normal M1 - M
    axis_point: tuple[float, float, float] | None = None  # cylinder: M1, axis M1 - M
    diameter: float | None = None  # cylinder, sphere (m)
    corner1: tuple[float, float, float] | None = None  # parallelogram: M1, side L1 = M1 - M
    corner2: tuple[float, float, float] | None = None  # parallelogram: M2, side L2 = M2 - M
    slide: str = "free"  # "free", "tied" or "friction"
    friction: float = 0.0  # Coulomb coefficient mu
    friction_filter: tuple[str, float] | None = None  # ("coefficient"|"steps"|"frequency", x)
    secondary: Secondary = field(default_factory=Secondary)
    motion: Motion | None = None  # None: a fixed wall


@dataclass(frozen=True)
class BoundarySpec:
    """Prescribed velocity (zero: a clamp) of some components of a named node set."""

    group: str  # a named physical group of the mesh
    velocity: tuple = (0.0, 0.0, 0.0)  # m/s: [vx, vy, vz], or rows (t, vx, vy, vz)
    components: str = "xyz"  # the global components prescribed; the others stay free


@dataclass(frozen=True)
class Output:
    directory: Path = Path("results")
    frames: int = 0  # number of PNG frames over the run; 0: no pictures
    fields: int = 0  # snapshots of displacement, velocity, von Mises in fields.xdmf; 0: none
    history_interval: int = 1  # steps between rows of energy.csv and walls.csv
    color: str = "normal_velocity"  # frames coloured by: "normal_velocity", "speed", "displacement"
    plot: bool = True  # histories.png: energies and wall forces over time


@dataclass(frozen=True)
class Scene:
    source: str  # file name used in messages
    run: RunSettings
    mesh: MeshSpec | None  # None: the body is given to build_simulation
    material: Material
    initial: Initial
    walls: tuple[WallSpec, ...] = ()
    output: Output = field(default_factory=Output)
    gravity: tuple[float, float, float] | None = None  # m/s^2
    boundaries: tuple[BoundarySpec, ...] = ()


# --- reading -----------------------------------------------------------------


def load_scene(path: str | Path, overrides: list[str] = ()) -> Scene:
    """Read, override (``key.path=value``) and validate the scene file at ``path``."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(f"{path}: scene file not found")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"{path}: not valid TOML: {err}") from None
    for item in overrides:
        apply_override(raw, item, str(path))
    return parse_scene(raw, source=str(path), base=path.parent)


def apply_override(raw: dict, item: str, source: str = "--set") -> None:
    """Apply ``key.path=value`` (``wall[0].slide="tied"``) to the raw scene, in place.

    The value is read as a TOML value; a bare word that is not one is taken as a string.
    """
    key, sep, text = item.partition("=")
    if not sep or not key.strip():
        raise SceneError(f"{source}: --set {item!r}: expected key.path=value")
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        value = text.strip()
    node: Any = raw
    parts = _split_key(key.strip(), source)
    for i, part in enumerate(parts[:-1]):
        nxt = parts[i + 1]
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise SceneError(f"{source}: --set {key}: index {part} does not exist")
            node = node[part]
        else:
            node = node.setdefault(part, [] if isinstance(nxt, int) else {})
    last = parts[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise SceneError(f"{source}: --set {key}: index {last} does not exist")
    node[last] = value


def _split_key(key: str, source: str) -> list[str | int]:
    parts: list[str | int] = []
    for word in key.split("."):
        name, _, rest = word.partition("[")
        if name:
            parts.append(name)
        while rest:
            index, _, rest = rest.partition("]")
            if not index.isdigit():
                raise SceneError(f"{source}: --set {key}: bad index [{index}]")
            parts.append(int(index))
            rest = rest.removeprefix("[")
    return parts


# --- validation ----------------------------------------------------------------


class _Table:
    """Typed access to one TOML table that reports errors with the key path."""

    def __init__(self, raw: Any, path: str, source: str, allowed: tuple[str, ...]):
        self.path, self.source = path, source
        if not isinstance(raw, dict):
            self.fail(path, "must be a table")
        self.raw = raw
        for key in raw:
            if key not in allowed:
                hint = (
                    difflib.get_close_matches(key, allowed, n=1)
                    or [name for name in allowed if name.startswith(key) or key.startswith(name)][
                        :1
                    ]
                )
                tip = f" (did you mean '{hint[0]}'?)" if hint else ""
                self.fail(self.key(key), f"unknown key{tip}; allowed: {', '.join(allowed)}")

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def fail(self, key: str, message: str):
        raise SceneError(f"{self.source}: {key}: {message}")

    def get(self, name: str, default: Any = ...) -> Any:
        if name not in self.raw:
            if default is ...:
                self.fail(self.key(name), "missing")
            return default
        return self.raw[name]

    def number(self, name, default=..., *, low=None, high=None, low_open=True, high_open=False):
        value = self.get(name, default)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(self.key(name), f"must be a number, got {value!r}")
        value = float(value)
        ok = math.isfinite(value)
        if low is not None:
            ok &= value > low if low_open else value >= low
        if high is not None:
            ok &= value < high if high_open else value <= high
        if not ok:
            lo = "" if low is None else ("(" if low_open else "[") + f"{low:g}"
            hi = "" if high is None else f"{high:g}" + (")" if high_open else "]")
            span = f"in {lo or '(-inf'}, {hi or 'inf)'}"
            self.fail(self.key(name), f"must be a finite number {span}, got {value:g}")
        return value

    def integer(self, name, default=..., *, low=0):
        value = self.get(name, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            self.fail(self.key(name), f"must be an integer >= {low}, got {value!r}")
        return value

    def vector(self, name, default=..., size: int = 3) -> tuple[float, ...]:
        """``size`` finite numbers: the components x, y (, z)."""
        value = self.get(name, default)
        if (
            not isinstance(value, (list, tuple))
            or len(value) != size
            or not all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in value)
            or not all(math.isfinite(c) for c in value)
        ):
            names = ", ".join("xyz"[:size])
            self.fail(self.key(name), f"must be {size} finite numbers [{names}], got {value!r}")
        return tuple(float(c) for c in value)

    def choice(self, name, choices: tuple[str, ...], default=...) -> str:
        value = self.get(name, default)
        if value not in choices:
            allowed = ", ".join(map(repr, choices))
            self.fail(self.key(name), f"must be one of {allowed}, got {value!r}")
        return value


def parse_scene(raw: dict, source: str = "<scene>", base: Path = Path(".")) -> Scene:
    """Validate the raw TOML mapping ``raw`` into a :class:`Scene`."""
    top = _Table(
        raw,
        "",
        source,
        ("run", "mesh", "material", "initial", "gravity", "boundary", "wall", "output"),
    )

    t = _Table(
        top.get("run"),
        "run",
        source,
        ("end_time", "dt_scale", "dt", "max_energy_error", "min_dt"),
    )
    run = RunSettings(
        end_time=t.number("end_time", low=0.0),
        dt_scale=t.number("dt_scale", 0.9, low=0.0, high=1.0),
        dt=t.number("dt", None, low=0.0),
        max_energy_error=t.number("max_energy_error", 0.05, low=0.0),
        min_dt=t.number("min_dt", 0.0, low=0.0, low_open=False),
    )

    mesh = _mesh(top.get("mesh", {}), source, base)

    t = _Table(top.get("material"), "material", source, ("model", "density", "young", "poisson"))
    material = Material(
        model=t.choice("model", MATERIAL_MODELS),
        density=t.number("density", low=0.0),
        young=t.number("young", low=0.0),
        poisson=t.number("poisson", low=-1.0, high=0.5, high_open=True),
    )

    t = _Table(top.get("initial", {}), "initial", source, ("velocity",))
    initial = Initial(velocity=t.vector("velocity", (0.0, 0.0, 0.0)))

    gravity = None
    if "gravity" in top.raw:
        gravity = _Table(top.get("gravity"), "gravity", source, ("acceleration",)).vector(
            "acceleration"
        )

    walls_raw = top.get("wall", [])
    if not isinstance(walls_raw, list):
        top.fail("wall", "must be an array of tables: write [[wall]]")
    walls = tuple(
        _wall(_shape_table(w, f"wall[{i}]", source), f"wall[{i}]", source)
        for i, w in enumerate(walls_raw)
    )

    boundaries_raw = top.get("boundary", [])
    if not isinstance(boundaries_raw, list):
        top.fail("boundary", "must be an array of tables: write [[boundary]]")
    boundaries = tuple(_boundary(b, f"boundary[{i}]", source) for i, b in enumerate(boundaries_raw))

    t = _Table(
        top.get("output", {}),
        "output",
        source,
        ("directory", "frames", "fields", "history_interval", "color", "plot"),
    )
    directory = t.get("directory", "results")
    if not isinstance(directory, str):
        t.fail(t.key("directory"), f"must be a path string, got {directory!r}")
    output = Output(
        directory=Path(directory),
        frames=t.integer("frames", 0),
        fields=t.integer("fields", 0),
        history_interval=t.integer("history_interval", 1, low=1),
        color=t.choice("color", ("normal_velocity", "speed", "displacement"), "normal_velocity"),
        plot=t.choice("plot", (True, False), True),
    )
    return Scene(source, run, mesh, material, initial, walls, output, gravity, boundaries)


def _boundary(raw, path: str, source: str) -> BoundarySpec:
    t = _Table(raw, path, source, ("group", "velocity", "components"))
    group = t.get("group")
    if not isinstance(group, str):
        t.fail(t.key("group"), f"must be the name of a node set, got {group!r}")
    velocity = t.get("velocity", [0.0, 0.0, 0.0])
    if isinstance(velocity, list) and velocity and isinstance(velocity[0], list):
        velocity = _velocity_table(t)
    else:
        velocity = t.vector("velocity", (0.0, 0.0, 0.0))
    components = t.get("components", "xyz")
    if (
        not isinstance(components, str)
        or not components
        or any(c not in "xyz" for c in components)
        or len(set(components)) != len(components)
    ):
        t.fail(t.key("components"), f"must be some of the letters x, y, z once, got {components!r}")
    return BoundarySpec(group, velocity, "".join(sorted(components)))


# The keys of each mesh shape besides "shape", "noise" and the refinement keys.
MESH_SHAPES = {
    "bar": ("origin", "size", "axis", "element_size", "cell"),
    "round_bar": ("origin", "radius", "length", "axis", "element_size", "cell"),
    "plate": ("origin", "size", "layers", "axis", "element_size", "cell"),
    "plate_with_hole": (
        "origin",
        "size",
        "hole_radius",
        "hole_offset",
        "layers",
        "axis",
        "element_size",
        "cell",
    ),
}
_REFINE_KEYS = ("refine_point", "refine_size", "refine_radius")


def _mesh(raw: Any, source: str, base: Path) -> MeshSpec | None:
    shape_keys = tuple(dict.fromkeys(sum(MESH_SHAPES.values(), ())))
    t = _Table(raw, "mesh", source, ("shape", "file", *shape_keys, *_REFINE_KEYS, "noise"))
    if not t.raw:
        return None  # a mesh of one's own, given to build_simulation
    if "file" in t.raw:
        if "shape" in t.raw:
            t.fail("mesh", "give either 'shape' or 'file', not both")
        for key in (*shape_keys, *_REFINE_KEYS):
            if key in t.raw:
                t.fail(t.key(key), "is not a key of a mesh file (only 'file' and 'noise')")
        file = t.get("file")
        if not isinstance(file, str):
            t.fail(t.key("file"), f"must be a path string, got {file!r}")
        file = (base / file).resolve()
        if not file.is_file():
            t.fail(t.key("file"), f"mesh file not found: {file}")
        if file.suffix not in (".msh", ".geo"):
            t.fail(t.key("file"), f"must be a gmsh .msh or .geo file, got {file.name}")
        return MeshSpec(shape=None, file=file, noise=_noise(t))

    shape = t.choice("shape", tuple(MESH_SHAPES))
    for key in shape_keys:
        if key in t.raw and key not in MESH_SHAPES[shape]:
            owners = " or ".join(name for name, keys in MESH_SHAPES.items() if key in keys)
            allowed = ", ".join(MESH_SHAPES[shape])
            t.fail(
                t.key(key),
                f"is not a key of a {shape} (it belongs to a {owners}); "
                f"allowed: {allowed}, {', '.join(_REFINE_KEYS)}, noise",
            )
    values: dict[str, Any] = {}
    if shape == "round_bar":
        values["radius"] = t.number("radius", low=0.0)
        values["length"] = t.number("length", low=0.0)
    else:
        values["size"] = _positive_vector(t, "size")
    if shape in ("plate", "plate_with_hole") and "layers" in t.raw:
        values["layers"] = t.integer("layers", low=1)
    if shape == "plate_with_hole":
        values["hole_radius"] = r = t.number("hole_radius", low=0.0)
        values["hole_offset"] = dx, dy = t.vector("hole_offset", (0.0, 0.0), size=2)
        lx, ly, _ = values["size"]
        if abs(dx) + r >= lx / 2 or abs(dy) + r >= ly / 2:
            t.fail(
                t.key("hole_radius"),
                f"the hole (radius {r:g} m, centre {dx:g}, {dy:g} m from the plate's centre) "
                f"does not fit in the plate ({lx:g} x {ly:g} m): "
                "it needs |dx| + r < lx/2 and |dy| + r < ly/2",
            )
    element_size = t.number("element_size", low=0.0)
    if any(key in t.raw for key in _REFINE_KEYS):
        values["refine_point"] = t.vector("refine_point")
        values["refine_size"] = t.number("refine_size", low=0.0, high=element_size, high_open=True)
        values["refine_radius"] = t.number("refine_radius", 4 * element_size, low=0.0)
    return MeshSpec(
        shape=shape,
        origin=t.vector("origin", (0.0, 0.0, 0.0)),
        axis=_direction(t, "axis"),
        element_size=element_size,
        cell=t.choice("cell", ("hexahedron", "tetrahedron"), "hexahedron"),
        noise=_noise(t),
        **values,
    )


def _positive_vector(t: _Table, name: str):
    value = t.vector(name)
    if min(value) <= 0:
        t.fail(t.key(name), f"must be 3 positive lengths, got {list(value)}")
    return value


def _direction(t: _Table, name: str):
    value = t.vector(name, (0.0, 0.0, 1.0))
    if math.hypot(*value) == 0:
        t.fail(t.key(name), "must be a non-zero direction [x, y, z]")
    return value


def _noise(t: _Table):
    if "noise" not in t.raw:
        return None
    n = _Table(t.get("noise"), t.key("noise"), t.source, ("amplitude", "seed"))
    return n.number("amplitude", low=0.0), n.integer("seed", 0)


_SLIDES = {
    "free": "free",
    "tied": "tied",
    "friction": "friction",
    0: "free",
    1: "tied",
    2: "friction",
}
# The keys that define each wall shape besides ``point`` (M).
SHAPE_KEYS = {
    "plane": ("normal_point",),
    "cylinder": ("axis_point", "diameter"),
    "sphere": ("diameter",),
    "parallelogram": ("corner1", "corner2"),
}
_COMMON_KEYS = ("kind", "point", "slide", "friction", "friction_filter", "secondary", "motion")


def _shape_table(raw: Any, path: str, source: str) -> Any:
    """A wall given with a shape object (the Python API) as the table a scene file has:
    ``PlaneWall(...)`` alone, or a dict with ``shape = CylinderWall(...)`` and other keys."""
    if hasattr(raw, "kind") and hasattr(raw, "parameters"):
        return {"kind": raw.kind, **raw.parameters()}
    if not isinstance(raw, dict) or "shape" not in raw:
        return raw
    t = _Table(raw, path, source, tuple(raw))  # keys are checked with the table it becomes
    shape = raw["shape"]
    if not (hasattr(shape, "kind") and hasattr(shape, "parameters")):
        t.fail(
            t.key("shape"),
            "must be a wall shape: PlaneWall, CylinderWall, SphereWall or ParallelogramWall",
        )
    if "kind" in raw:
        t.fail(t.key("kind"), "give either 'kind' or 'shape', not both")
    rest = {key: value for key, value in raw.items() if key != "shape"}
    return {"kind": shape.kind, **shape.parameters(), **rest}


def _wall(raw: Any, path: str, source: str) -> WallSpec:
    kinds = tuple(SHAPE_KEYS)
    kind = raw.get("kind") if isinstance(raw, dict) else None
    shape_keys = SHAPE_KEYS.get(kind, ())
    t = _Table(raw, path, source, _COMMON_KEYS + sum(SHAPE_KEYS.values(), ()))
    t.choice("kind", kinds)
    for key in sorted(set(sum(SHAPE_KEYS.values(), ())) - set(shape_keys)):
        if key in t.raw:
            owners = " or ".join(k for k, keys in SHAPE_KEYS.items() if key in keys)
            t.fail(t.key(key), f"is not a key of a {kind} wall (it belongs to a {owners} wall)")
    point = t.vector("point")
    values: dict[str, Any] = {}
    for key in shape_keys:
        values[key] = t.number(key, low=0.0) if key == "diameter" else t.vector(key)

    def distinct(key):
        scale = max(math.hypot(*point), math.hypot(*values[key]))
        if math.dist(point, values[key]) <= 1e-10 * scale:
            t.fail(t.key(key), f"must differ from 'point' ({key} = point leaves no direction)")

    if kind == "plane":
        distinct("normal_point")
    elif kind == "cylinder":
        distinct("axis_point")
    elif kind == "parallelogram":
        distinct("corner1")
        distinct("corner2")
        l1 = [a - b for a, b in zip(values["corner1"], point, strict=True)]
        l2 = [a - b for a, b in zip(values["corner2"], point, strict=True)]
        cross = math.hypot(
            l1[1] * l2[2] - l1[2] * l2[1],
            l1[2] * l2[0] - l1[0] * l2[2],
            l1[0] * l2[1] - l1[1] * l2[0],
        )
        if cross <= 1e-10 * math.hypot(*l1) * math.hypot(*l2):
            t.fail(t.key("corner2"), "sides corner1 - point and corner2 - point are parallel")

    slide_raw = t.get("slide", "free")
    if isinstance(slide_raw, bool) or slide_raw not in _SLIDES:
        t.fail(
            t.key("slide"), f"must be 'free', 'tied', 'friction' (or 0, 1, 2), got {slide_raw!r}"
        )
    slide = _SLIDES[slide_raw]
    friction = 0.0
    if slide == "friction":
        friction = t.number("friction", low=0.0, low_open=False)
    elif "friction" in t.raw:
        t.fail(t.key("friction"), f"needs slide = 'friction' (slide is '{slide}')")
    friction_filter = None
    if "friction_filter" in t.raw:
        if slide != "friction":
            t.fail(t.key("friction_filter"), f"needs slide = 'friction' (slide is '{slide}')")
        f = _Table(
            t.get("friction_filter"),
            t.key("friction_filter"),
            source,
            ("coefficient", "steps", "frequency"),
        )
        if len(f.raw) != 1:
            f.fail(f.path, "give exactly one of coefficient, steps, frequency")
        (how,) = f.raw
        if how == "coefficient":
            friction_filter = (how, f.number(how, low=0.0, high=1.0))
        elif how == "steps":
            friction_filter = (how, f.number(how, low=2 * math.pi, low_open=False))
        else:
            friction_filter = (how, f.number(how, low=0.0))

    sec = _Table(
        t.get("secondary", {}), t.key("secondary"), source, ("search_distance", "add", "exclude")
    )
    secondary = Secondary(
        search_distance=sec.number("search_distance", None, low=0.0, low_open=False),
        add=_names(sec, "add"),
        exclude=_names(sec, "exclude"),
    )

    motion = None
    if "motion" in t.raw:
        mo = _Table(t.get("motion"), t.key("motion"), source, ("mass", "velocity"))
        mass = mo.number("mass", None, low=0.0)
        velocity = mo.get("velocity")
        if isinstance(velocity, list) and velocity and isinstance(velocity[0], list):
            if mass is not None:
                mo.fail(mo.key("mass"), "a velocity table prescribes the motion: drop 'mass'")
            velocity = _velocity_table(mo)
        else:
            velocity = mo.vector("velocity")
        motion = Motion(mass, velocity)
    return WallSpec(
        kind,
        point,
        **values,
        slide=slide,
        friction=friction,
        friction_filter=friction_filter,
        secondary=secondary,
        motion=motion,
    )


def _names(t: _Table, name: str) -> tuple[str, ...]:
    value = t.get(name, [])
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        t.fail(t.key(name), f"must be a list of node-set names, got {value!r}")
    return tuple(value)


def _velocity_table(t: _Table) -> tuple:
    rows = t.get("velocity")
    ok = all(
        isinstance(r, list)
        and len(r) == 4
        and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in r
        )
        for r in rows
    )
    if not ok or any(b[0] <= a[0] for a, b in itertools.pairwise(rows)):
        t.fail(t.key("velocity"), "a table must be rows [t, vx, vy, vz] with increasing t")
    return tuple(tuple(float(x) for x in r) for r in rows)
