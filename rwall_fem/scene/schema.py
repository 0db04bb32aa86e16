"""The scene format, written once: every table a dataclass, every key a ``key(...)``.

Each key carries its type, unit, range, default and a one-line doc; rules that
tie keys together are functions next to their table, their docstring the line
the reference page prints. The validation (:func:`~rwall_fem.scene.keys.read_table`),
``docs/reference/scene.md`` and ``scene.schema.json``
(:mod:`rwall_fem.scene.reference`) all come from here.
"""

from __future__ import annotations

import dataclasses

import math
from dataclasses import dataclass, replace
from pathlib import Path

from rwall_fem.scene.keys import (
    Choice,
    Curve,
    Each,
    Factor,
    Flag,
    Identifier,
    Integer,
    Letters,
    MeshFile,
    Names,
    NodeSets,
    Real,
    Sub,
    Text,
    Variants,
    Vector,
    Velocity,
    did_you_mean,
    key,
    rule,
    show,
    table,
)
from rwall_fem.scene.rigid_bodies import RigidBodySpec
from rwall_fem.scene.view import ViewSpec
from rwall_fem.units import parse_system

__all__ = [
    "MATERIAL_MODELS",
    "PLASTIC_MODELS",
    "MESH_SHAPES",
    "SHAPE_KEYS",
    "SHAPE_REGIONS",
    "AddedMassSpec",
    "BoundarySpec",
    "ContactSpec",
    "Damping",
    "Element",
    "Failure",
    "Heating",
    "Initial",
    "LoadSpec",
    "Material",
    "MeshSpec",
    "PIECE_SHAPES",
    "PieceSpec",
    "Motion",
    "Output",
    "PartSpec",
    "RunSettings",
    "SHELL_KEYS",
    "SURFACE_CELLS",
    "Scene",
    "Secondary",
    "WallSpec",
]

# Small strain (constant stiffness), the large-deformation hyperelastic models, and the
# elasto-plastic ones (J2 with isotropic hardening; Johnson-Cook).
MATERIAL_MODELS = (
    "linear_elastic",
    "saint_venant_kirchhoff",
    "neo_hookean",
    "elastic_plastic",
    "johnson_cook",
)
PLASTIC_MODELS = ("elastic_plastic", "johnson_cook")
_ELASTIC_KEYS = ("density", "young", "poisson")
# The keys of each material model besides "model".
MATERIAL_KEYS = {model: _ELASTIC_KEYS for model in MATERIAL_MODELS} | {
    "elastic_plastic": (
        *_ELASTIC_KEYS,
        "hardening",
        "yield_stress",
        "hardening_modulus",
        "hardening_coefficient",
        "hardening_exponent",
        "hardening_curve",
        "failure",
        "max_flow_stress",
    ),
    "johnson_cook": (
        *_ELASTIC_KEYS,
        "yield_stress",
        "hardening_coefficient",
        "hardening_exponent",
        "strain_rate_coefficient",
        "reference_strain_rate",
        "heating",
        "failure",
        "max_flow_stress",
    ),
}
# The failure criteria and their keys besides "criterion".
FAILURE_KEYS = {
    "plastic_strain": ("plastic_strain",),
    "johnson_cook": ("d1", "d2", "d3", "d4", "d5", "reference_strain_rate"),
}

# The keys of each mesh shape besides "shape", "noise" and the refinement keys.
MESH_SHAPES = {
    "bar": ("origin", "size", "axis", "element_size", "cell", "front_length"),
    "round_bar": ("origin", "radius", "length", "axis", "element_size", "cell", "front_length"),
    "plate": (
        "origin", "size", "layers", "axis", "element_size", "cell", "bottom_layer", "top_layer",
    ),
    "plate_with_hole": (
        "origin",
        "size",
        "hole_radius",
        "hole_offset",
        "layers",
        "axis",
        "element_size",
        "cell",
        "bottom_layer",
        "top_layer",
    ),
    "tube": (
        "origin", "section", "width", "length", "axis", "element_size", "cell",
        "trigger_amplitude", "trigger_wavelength",
    ),
}  # fmt: skip
# The regions (gmsh physical volumes) of each built-in shape: always "body"; the others
# when their key is above 0 (meshes/sweep.geo).
SHAPE_REGIONS = {
    "bar": {"front": "front_length"},
    "round_bar": {"front": "front_length"},
    "plate": {"bottom_layer": "bottom_layer", "top_layer": "top_layer"},
    "plate_with_hole": {"bottom_layer": "bottom_layer", "top_layer": "top_layer"},
    "tube": {},
}
_REFINE_KEYS = ("refine_point", "refine_size", "refine_radius")

# The keys that define each wall shape besides ``point`` (M).
SHAPE_KEYS = {
    "plane": ("normal_point",),
    "cylinder": ("axis_point", "diameter"),
    "sphere": ("diameter",),
    "parallelogram": ("corner1", "corner2"),
}
_WALL_KEYS = ("point", "slide", "friction", "friction_filter", "secondary", "motion")


# --- [run] -------------------------------------------------------------------------


@table(
    "How long, with which time step, and within which limits (`rwall-fem run --lift-limits`"
    " lifts them)."
)
@dataclass(frozen=True)
class RunSettings:
    end_time: float = key(Real(low=0.0), unit="s", doc="simulated time")
    time_step: str | None = key(
        Choice(("adaptive", "fixed")),
        None,
        doc="adaptive: dt_scale x the stable step of the deformed cells, every step (Radioss, "
        "LS-DYNA); fixed: dt_scale x the stable step at rest (or dt) for the whole run",
        default_doc="adaptive; fixed when dt is given",
    )
    dt_scale: float = key(
        Real(low=0.0, high=1.0),
        0.9,
        doc="the step as a fraction of the stable step (Radioss's /DT scale, LS-DYNA's TSSFAC)",
    )
    dt: float | None = key(
        Real(low=0.0),
        None,
        unit="s",
        doc="a fixed step instead; refused above the stable limit (checked with the body)",
        default_doc="from dt_scale",
    )
    dt_min: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="s",
        doc="adaptive step: the smallest step the run takes; below it, dt_min_action",
        default_doc="0: none",
    )
    dt_min_action: str = key(
        Choice(("stop", "mass_scaling", "erode")),
        "stop",
        doc="stop: the run stops (exit 3, with a checkpoint); mass_scaling: mass is added to "
        "the cells that would go below dt_min, just enough to hold it (LS-DYNA's DT2MS); "
        "erode: those cells, and inverted ones, are eroded (Radioss's /DT/BRICK/DEL)",
    )
    max_added_mass: float = key(
        Real(low=0.0),
        0.05,
        doc="mass scaling: the run stops when the added mass passes this fraction of the "
        "body's mass",
    )
    max_energy_error: float = key(
        Real(low=0.0),
        0.05,
        doc="guard: the run stops (exit 3) when the energy balance error exceeds it",
    )
    max_cells: float = key(
        Real(low=0.0),
        2e6,
        unit="cells",
        doc="limit: a mesh estimated (before meshing) or counted (after) above it is refused;"
        " about 1.7 kB per hexahedron, 0.8 kB per tetrahedron",
    )
    max_steps: float = key(
        Real(low=0.0),
        1e7,
        unit="steps",
        doc="limit: a run of more steps (estimated before meshing, counted with the stable"
        " step at rest) is refused; an adaptive run stops when it reaches it",
    )
    max_frames: int = key(
        Integer(low=0),
        1000,
        doc="limit: output.frames and output.fields above it are refused",
    )


_ADAPTIVE_ONLY = {"not": {"anyOf": [{"required": k} for k in
                           (["dt_min"], ["dt_min_action"], ["max_added_mass"])]}}  # fmt: skip


@rule(
    RunSettings,
    json=[
        {
            "not": {
                "required": ["dt", "time_step"],
                "properties": {"time_step": {"const": "adaptive"}},
            }
        },
        {"if": {"required": ["dt"]}, "then": _ADAPTIVE_ONLY},
        {
            "if": {"required": ["time_step"], "properties": {"time_step": {"const": "fixed"}}},
            "then": _ADAPTIVE_ONLY,
        },
        {
            "if": {
                "required": ["dt_min_action"],
                "properties": {"dt_min_action": {"enum": ["mass_scaling", "erode"]}},
            },
            "then": {"required": ["dt_min"], "properties": {"dt_min": {"exclusiveMinimum": 0}}},
        },
    ],
)
def _one_kind_of_step(v, raw, fail):
    """A given dt is a fixed step: time_step is then 'fixed' (its default); dt_min, mass
    scaling and erosion below dt_min are for the adaptive step, and need dt_min > 0."""
    if v["dt"] is not None:
        if v["time_step"] == "adaptive":
            fail("dt", "is a fixed step, and time_step is 'adaptive': drop dt (dt_scale sets the "
                 "adaptive step) or set time_step = 'fixed'")  # fmt: skip
        v["time_step"] = "fixed"
    elif v["time_step"] is None:
        v["time_step"] = "adaptive"
    if v["time_step"] == "fixed":
        for name in ("dt_min", "dt_min_action", "max_added_mass"):
            if name in raw:
                fail(name, "needs time_step = 'adaptive' (a fixed step never falls)")
    elif v["dt_min_action"] != "stop" and not v["dt_min"] > 0.0:
        what = {"mass_scaling": "mass scaling holds the step at", "erode": "erosion acts below"}
        fail("dt_min", f"missing: {what[v['dt_min_action']]} dt_min, which must be above 0")


# --- [mesh] ------------------------------------------------------------------------


@table("The noise: a reproducible random shift of every initial node coordinate.")
@dataclass(frozen=True)
class Noise:
    amplitude: float = key(
        Real(low=0.0), unit="m", doc="each coordinate moves by at most this, uniformly"
    )
    seed: int = key(
        Integer(0, 2**64 - 1, why="the seed of a 64-bit generator"),
        0,
        doc="the same seed gives the same shift on any number of ranks",
    )


@table(
    "The body: a built-in shape (`meshes/<shape>.geo`) or a gmsh file; no [mesh]: a body "
    "given to `build_simulation`.",
    variants=Variants(
        "shape",
        MESH_SHAPES,
        common=(*_REFINE_KEYS, "noise"),
        instead=("file", "a mesh file", ("noise",)),
    ),
)
@dataclass(frozen=True)
class MeshSpec:
    shape: str | None = key(
        Choice(tuple(MESH_SHAPES)),
        None,
        required=True,
        doc="the built-in body",
        default_doc="required, or file",
    )
    file: Path | None = key(
        MeshFile(), None, doc="a gmsh .msh or .geo file instead of a shape and its keys"
    )
    origin: tuple[float, float, float] = key(
        Vector(),
        (0.0, 0.0, 0.0),
        unit="m",
        doc="lowest corner (bar, plates) or centre of the bottom face (round bar); "
        "the body turns about it",
    )
    size: tuple[float, float, float] | None = key(
        Vector(kind="positive"),
        None,
        required=True,
        unit="m",
        doc="lengths along the body's own x, y, z (plates: lx, ly, thickness)",
    )
    radius: float | None = key(Real(low=0.0), None, required=True, unit="m", doc="of the bar")
    length: float | None = key(
        Real(low=0.0), None, required=True, unit="m", doc="of the bar or tube, along its own z"
    )
    section: str = key(
        Choice(("square", "circle")), "square", doc="the tube's cross-section (mid-surface)"
    )
    width: float | None = key(
        Real(low=0.0),
        None,
        required=True,
        unit="m",
        doc="the tube's side (square) or diameter (circle), of its mid-surface",
    )
    trigger_amplitude: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="m",
        doc="tubes: dents of this depth over the last trigger_wavelength before the top end, "
        "where a crush should start to fold (a square's faces alternately in and out)",
        default_doc="0: none",
    )
    trigger_wavelength: float | None = key(
        Real(low=0.0),
        None,
        unit="m",
        doc="tubes: the length of one dent in and one out, at the top end",
        default_doc="required with trigger_amplitude > 0",
    )
    hole_radius: float | None = key(
        Real(low=0.0), None, required=True, unit="m", doc="of the through-hole"
    )
    hole_offset: tuple[float, float] = key(
        Vector(2), (0.0, 0.0), unit="m", doc="hole centre - plate centre, along its own x, y"
    )
    layers: int = key(
        Integer(low=1),
        0,
        doc="elements through the thickness",
        default_doc="the fewest at most element_size thick",
    )
    axis: tuple[float, float, float] = key(
        Vector(kind="direction"),
        (0.0, 0.0, 1.0),
        doc="where the body's own z points (it turns about origin)",
    )
    element_size: float | None = key(
        Real(low=0.0), None, required=True, unit="m", doc="target edge length"
    )
    cell: str = key(
        Choice(("hexahedron", "tetrahedron", "quadrilateral", "triangle")),
        "hexahedron",
        doc="the cell type; quadrilateral, triangle: the plate's mid-surface in shells "
        "(element.thickness, by default the plate's)",
    )
    front_length: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="m",
        doc="bars: the first length along their own z, from origin, is the region 'front' "
        "(the rest: 'body'), a part of its own with [[part]]",
        default_doc="0: one region, 'body'",
    )
    bottom_layer: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="m",
        doc="plates: a layer of this thickness at their bottom face is the region 'bottom_layer'",
        default_doc="0: none",
    )
    top_layer: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="m",
        doc="plates: a layer of this thickness at their top face is the region 'top_layer'",
        default_doc="0: none",
    )
    refine_point: tuple[float, float, float] | None = key(
        Vector(), None, unit="m", doc="centre of a zone of smaller cells, in scene coordinates"
    )
    refine_size: float | None = key(
        Real(low=0.0, high="element_size", high_open=True),
        None,
        unit="m",
        doc="element size at refine_point",
    )
    refine_radius: float | None = key(
        Real(low=0.0),
        None,
        unit="m",
        doc="distance over which the size grows back to element_size",
        default_doc="4 x element_size",
    )
    noise: tuple[float, int] | None = key(
        Sub(Noise, then=lambda n: (n.amplitude, n.seed)),
        None,
        doc="(amplitude, seed): random shift of the initial coordinates",
    )


@rule(MeshSpec)
def _hole_fits(v, raw, fail):
    """A plate's hole lies inside the plate: |dx| + r < lx/2 and |dy| + r < ly/2."""
    if v["shape"] != "plate_with_hole":
        return
    r, (dx, dy), (lx, ly, _) = v["hole_radius"], v["hole_offset"], v["size"]
    if abs(dx) + r >= lx / 2 or abs(dy) + r >= ly / 2:
        fail(
            "hole_radius",
            f"the hole (radius {r:g} m, centre {dx:g}, {dy:g} m from the plate's centre) "
            f"does not fit in the plate ({lx:g} x {ly:g} m): "
            "it needs |dx| + r < lx/2 and |dy| + r < ly/2",
        )


@rule(
    MeshSpec,
    json=[
        {
            "dependentRequired": {
                "refine_point": ["refine_size"],
                "refine_size": ["refine_point"],
                "refine_radius": ["refine_point", "refine_size"],
            }
        }
    ],
)
def _refinement_comes_whole(v, raw, fail):
    """refine_point and refine_size come together; refine_radius needs them."""
    given = [name for name in _REFINE_KEYS if name in raw]
    if not given:
        return
    for name in ("refine_point", "refine_size"):
        if name not in raw:
            fail(name, f"missing ({' and '.join(given)} need it)")
    if v["refine_radius"] is None:
        v["refine_radius"] = 4 * v["element_size"]


@rule(MeshSpec)
def _surface_cells_are_a_plate(v, raw, fail):
    """Shells (cell quadrilateral or triangle) are the mid-surface of a plate or a tube
    (a tube is only shells: quadrilateral by default); no layers, bottom_layer, top_layer
    or refinement. A tube's trigger has a wavelength within its length."""
    if v["shape"] == "tube":
        if "cell" not in raw:
            v["cell"] = "quadrilateral"
        if v["cell"] not in SURFACE_CELLS:
            fail("cell", f"a tube is a mid-surface of shells: 'quadrilateral' or 'triangle', "
                 f"got {v['cell']!r}")  # fmt: skip
        wavelength = v["trigger_wavelength"]
        if v["trigger_amplitude"] > 0.0 and wavelength is None:
            fail("trigger_wavelength", "missing: the dents of trigger_amplitude need it")
        if wavelength is not None and wavelength > v["length"]:
            fail("trigger_wavelength", f"{wavelength:g} m is longer than the tube "
                 f"({v['length']:g} m)")  # fmt: skip
    if v["shape"] is None or v["cell"] not in SURFACE_CELLS:
        return
    if v["shape"] not in ("plate", "tube"):
        fail("cell", f"{v['cell']!r} (shells) is for the shapes 'plate' and 'tube'; "
             f"a {v['shape']} is hexahedron or tetrahedron")  # fmt: skip
    for name in ("layers", "bottom_layer", "top_layer", *_REFINE_KEYS):
        if name in raw:
            fail(name, f"is for solid plates; a plate of {v['cell']} cells is one mid-surface "
                 "of shells: leave it out")  # fmt: skip


def _own_frame(axis) -> list[list[float]]:
    """The rows of R^T, where R turns z onto ``axis``: meshing.rotation_to, without NumPy."""
    n = math.hypot(*axis)
    b = [a / n for a in axis]
    c = b[2]
    if c < -1 + 1e-12:
        return [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
    k = (-b[1], b[0], 0.0)
    K = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]]
    KK = [[sum(K[i][m] * K[m][j] for m in range(3)) for j in range(3)] for i in range(3)]
    R = [[(i == j) + K[i][j] + KK[i][j] / (1 + c) for j in range(3)] for i in range(3)]
    return [[R[j][i] for j in range(3)] for i in range(3)]


def _body_box(v) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The body's box (lowest, highest corner) in its own frame, relative to ``origin``."""
    if v["shape"] == "round_bar":
        r = v["radius"]
        return (-r, -r, 0.0), (r, r, v["length"])
    return (0.0, 0.0, 0.0), v["size"]


@rule(MeshSpec)
def _regions_fit(v, raw, fail):
    """A bar's front_length is shorter than the bar; a plate's bottom_layer and top_layer
    leave some of its thickness, and a given layers count is at least one per region."""
    shape = v["shape"]
    if shape in ("bar", "round_bar"):
        length = v["size"][2] if shape == "bar" else v["length"]
        if v["front_length"] >= length:
            fail(
                "front_length",
                f"{v['front_length']:g} m is not shorter than the bar ({length:g} m)",
            )
    elif shape in ("plate", "plate_with_hole"):
        thickness = v["size"][2]
        layers = [v["bottom_layer"], v["top_layer"]]
        if sum(layers) >= thickness:
            key_ = "top_layer" if v["top_layer"] else "bottom_layer"
            fail(
                key_,
                f"bottom_layer + top_layer = {sum(layers):g} m leave nothing of the plate's "
                f"thickness ({thickness:g} m)",
            )
        regions = 1 + sum(x > 0 for x in layers)
        if 0 < v["layers"] < regions:
            fail("layers", f"{v['layers']} is fewer than one per region ({regions})")


@rule(MeshSpec)
def _refinement_is_meshable(v, raw, fail):
    """refine_size is at least 1e-5 x element_size: gmsh's section mesher crashed at a
    ratio of 1e-6."""
    if v["refine_size"] is not None and v["refine_size"] < 1e-5 * v["element_size"]:
        fail(
            "refine_size",
            f"{v['refine_size']:g} m is less than 1e-5 x element_size "
            f"({1e-5 * v['element_size']:g} m): gmsh cannot grade a mesh over that ratio",
        )


@rule(MeshSpec)
def _refinement_reaches_the_body(v, raw, fail):
    """A refine_point lies within refine_radius of the body's box (origin, size or radius
    and length, turned onto axis): farther, nothing would be refined."""
    if v["shape"] is None or v["refine_point"] is None:
        return
    low, high = _body_box(v)
    shifted = [p - o for p, o in zip(v["refine_point"], v["origin"], strict=True)]
    own = [sum(r * s for r, s in zip(row, shifted, strict=True)) for row in _own_frame(v["axis"])]
    gap = math.hypot(*(max(lo - q, 0.0, q - hi) for q, lo, hi in zip(own, low, high, strict=True)))
    if gap > v["refine_radius"]:
        box = " x ".join(f"[{lo:g}, {hi:g}]" for lo, hi in zip(low, high, strict=True))
        fail(
            "refine_point",
            f"is {gap:.3g} m from the body, farther than refine_radius ({v['refine_radius']:g} m):"
            f" nothing would be refined; the body is origin + {box} m in its own frame "
            "(its z along axis)",
        )


@rule(MeshSpec)
def _noise_is_small(v, raw, fail):
    """The noise amplitude is at most 0.1 x the smallest element size (element_size,
    refine_size): more distorts the elements and shrinks the stable step."""
    if v["shape"] is None or v["noise"] is None:
        return
    h = min(v["element_size"], v["refine_size"] or math.inf)
    amplitude = v["noise"][0]
    if amplitude > 0.1 * h:
        fail(
            "noise.amplitude",
            f"{amplitude:g} m is more than 0.1 x the smallest element size ({h:g} m): "
            f"it would distort the elements and shrink the stable step; at most {0.1 * h:g} m",
        )


# --- [[piece]] ---------------------------------------------------------------------

# The built-in shapes a piece may be (the swept solids) and their keys: a [mesh]'s but the
# cell, which every piece shares (the body has one cell type).
PIECE_SHAPES = {
    shape: tuple(name for name in MESH_SHAPES[shape] if name != "cell")
    for shape in ("bar", "round_bar", "plate", "plate_with_hole")
}


def _piece_fields() -> list[tuple]:
    """The fields of a piece: its name, then [mesh]'s keys of the piece shapes, in their
    order there (a key's bounds refer to keys before it), the shape and cell its own."""
    own = {
        "shape": key(Choice(tuple(PIECE_SHAPES)), None, required=True,
                     doc="the built-in solid shape"),
        "cell": key(Choice(("hexahedron", "tetrahedron")), "hexahedron",
                    doc="the cell type, the same in every piece"),
    }  # fmt: skip
    used = {"shape", *_REFINE_KEYS, *(n for names in PIECE_SHAPES.values() for n in names)}
    fields = [("name", str, key(
        Identifier("a piece name"),
        doc="its region's name (a part's volumes; a [[part]] of that name takes it), and the "
        "prefix of its other regions and face groups (rod_front, rod_top, ...)",
    ))]  # fmt: skip
    for f in dataclasses.fields(MeshSpec):
        if f.name in used or f.name == "cell":
            made = own.get(f.name) or dataclasses.field(default=f.default, metadata=f.metadata)
            fields.append((f.name, f.type, made))
    return fields


PieceSpec = table(
    "A piece of the body: a built-in solid shape placed on its own (the pieces of [[piece]] "
    "stand instead of [mesh]); its region, named after it, is a part with [[part]].",
    variants=Variants("shape", PIECE_SHAPES, common=("name", "cell", *_REFINE_KEYS),
                      noun="a {} piece"),  # fmt: skip
)(dataclasses.make_dataclass("PieceSpec", _piece_fields(), frozen=True, kw_only=True))
PieceSpec.__module__ = __name__


for _check in (_hole_fits, _refinement_comes_whole, _regions_fit, _refinement_is_meshable,
               _refinement_reaches_the_body):  # fmt: skip
    rule(PieceSpec, json=_check.json)(_check)


# --- [material], [element], [initial], [gravity] ------------------------------------


@table(
    "Adiabatic heating and thermal softening of a Johnson-Cook material (Radioss LAW2's "
    "thermal terms); no [material.heating]: none.",
)
@dataclass(frozen=True)
class Heating:
    softening_exponent: float = key(
        Real(low=0.0), doc="m in the softening factor 1 - T*^m, T* = (T - T_room)/(T_melt - T_room)"
    )
    melting_temperature: float = key(Real(low=0.0), unit="K", doc="T_melt")
    specific_heat: float = key(Real(low=0.0), unit="J/(kg K)", doc="heat capacity per mass")
    room_temperature: float = key(
        Real(low=0.0), 293.15, unit="K", doc="T_room, also the initial temperature"
    )
    taylor_quinney: float = key(
        Real(low=0.0, low_open=False, high=1.0),
        0.9,
        doc="share of the plastic work that heats the material",
    )


@rule(Heating)
def _melting_above_room(v, raw, fail):
    """melting_temperature is above room_temperature."""
    if v["melting_temperature"] <= v["room_temperature"]:
        fail(
            "melting_temperature",
            f"must be above room_temperature ({v['room_temperature']:g} K), "
            f"got {v['melting_temperature']:g} K",
        )


@table(
    "How the material fails (LS-DYNA's *MAT_ADD_EROSION and MAT_015's D1-D5, Radioss's "
    "/FAIL/JOHNSON): damage D = sum d(eps_p) / eps_f per integration point; a cell whose "
    "point reaches D = 1 is eroded. No [material.failure]: none.",
    variants=Variants("criterion", FAILURE_KEYS, noun="the {} criterion"),
)
@dataclass(frozen=True)
class Failure:
    criterion: str = key(
        Choice(tuple(FAILURE_KEYS)),
        doc="plastic_strain: a constant equivalent plastic strain at failure; johnson_cook: "
        "eps_f = [d1 + d2 exp(d3 sigma*)] [1 + d4 ln max(rate / reference_strain_rate, 1)] "
        "[1 + d5 T*], sigma* the stress triaxiality",
    )
    plastic_strain: float | None = key(
        Real(low=0.0), None, required=True, doc="eps_f, the equivalent plastic strain at failure"
    )
    d1: float | None = key(Real(), None, required=True, doc="D1 of eps_f")
    d2: float | None = key(Real(), None, required=True, doc="D2 of eps_f")
    d3: float | None = key(Real(), None, required=True, doc="D3 of eps_f (negative for metals)")
    d4: float = key(Real(), 0.0, doc="D4 of eps_f, its rate term")
    d5: float = key(
        Real(),
        0.0,
        doc="D5 of eps_f, its temperature term (T* as in the flow stress: needs "
        "[material.heating], without which T* stays 0)",
    )
    reference_strain_rate: float | None = key(
        Real(low=0.0),
        None,
        unit="1/s",
        doc="the rate of the d4 term's reference",
        default_doc="the material's reference_strain_rate (johnson_cook), else 1",
    )


@table(
    "The body's material: one law for the whole body.",
    variants=Variants("model", MATERIAL_KEYS, noun="the {} model"),
)
@dataclass(frozen=True)
class Material:
    model: str = key(
        Choice(MATERIAL_MODELS),
        doc="linear_elastic: small strain; saint_venant_kirchhoff, neo_hookean: hyperelastic, "
        "large deformation; elastic_plastic (J2, isotropic hardening), johnson_cook: "
        "elasto-plastic, large deformation",
    )
    density: float = key(Real(low=0.0), unit="kg/m^3", doc="mass density")
    young: float = key(Real(low=0.0), unit="Pa", doc="Young's modulus")
    poisson: float = key(Real(low=-1.0, high=0.5, high_open=True), doc="Poisson's ratio")
    hardening: str | None = key(
        Choice(("linear", "power", "table")),
        None,
        required=True,
        doc="elastic_plastic: how the yield stress grows with the equivalent plastic strain "
        "eps_p: linear A + H eps_p, power A + B eps_p^n, or a table",
    )
    yield_stress: float | None = key(
        Real(low=0.0),
        None,
        required=True,
        unit="Pa",
        when={"hardening": ("linear", "power")},
        doc="initial yield stress A",
    )
    hardening_modulus: float | None = key(
        Real(low=0.0, low_open=False),
        None,
        required=True,
        unit="Pa",
        when={"hardening": ("linear",)},
        doc="H, the slope of the yield stress against eps_p (0: perfectly plastic)",
    )
    hardening_coefficient: float | None = key(
        Real(low=0.0, low_open=False),
        None,
        required=True,
        unit="Pa",
        when={"hardening": ("power",)},
        doc="B in A + B eps_p^n",
    )
    hardening_exponent: float | None = key(
        Real(low=0.0, low_open=False, high=1.0),
        None,
        required=True,
        when={"hardening": ("power",)},
        doc="n in A + B eps_p^n",
    )
    hardening_curve: tuple | None = key(
        Curve(first_x=0.0, rows=64),
        None,
        required=True,
        unit="-, Pa",
        when={"hardening": ("table",)},
        doc="rows [eps_p, yield stress], the first at eps_p = 0 (the initial yield stress)",
    )
    strain_rate_coefficient: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        doc="C in the rate factor 1 + C ln max(rate / reference_strain_rate, 1)",
    )
    reference_strain_rate: float = key(
        Real(low=0.0),
        1.0,
        unit="1/s",
        doc="the rate below which the flow stress is that of A + B eps_p^n",
    )
    heating: Heating | None = key(
        Sub(Heating),
        None,
        doc="adiabatic heating and thermal softening",
        default_doc="none: isothermal",
    )
    failure: Failure | None = key(
        Sub(Failure),
        None,
        doc="the failure criterion; failed cells are eroded",
        default_doc="none: the material never fails",
    )
    max_flow_stress: float | None = key(
        Real(low=0.0),
        None,
        unit="Pa",
        doc="the cap on the hardening law (Radioss LAW2's SIG_max0): the flow stress is "
        "min(hardening law, cap) times johnson_cook's rate and temperature factors, and does "
        "not harden where the cap holds; above the initial yield stress",
        default_doc="none: no cap",
    )

    @property
    def plastic(self) -> bool:
        """Whether the law is elasto-plastic (path-dependent: no stored energy)."""
        return self.model in PLASTIC_MODELS

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


@rule(Material)
def _damage_reference_rate(v, raw, fail):
    """failure.reference_strain_rate of the johnson_cook criterion defaults to the
    material's reference_strain_rate (1 /s for elastic_plastic)."""
    failure = v["failure"]
    if failure is not None and failure.criterion == "johnson_cook":
        if failure.reference_strain_rate is None:
            v["failure"] = replace(failure, reference_strain_rate=v["reference_strain_rate"])


@rule(Material)
def _cap_above_yield(v, raw, fail):
    """max_flow_stress lies above the initial yield stress (A, or the table's first row)."""
    cap = v["max_flow_stress"]
    if cap is None:
        return
    curve = v["hardening_curve"]
    initial = curve[0][1] if v["hardening"] == "table" and curve else v["yield_stress"]
    if initial is not None and cap <= initial:
        fail("max_flow_stress", f"{cap:g} Pa is not above the initial yield stress "
             f"{initial:g} Pa: the cap must lie above it (or leave max_flow_stress out)")


_HOURGLASS_FORMS = ("physical", "stiffness", "viscous")
# The cells of a body of shells, and the keys of [element] for shells and for solids.
SURFACE_CELLS = ("quadrilateral", "triangle")
SHELL_KEYS = ("thickness", "formulation", "points", "hourglass_coefficients", "shear_factor",
              "failed_share", "thickness_change", "hourglass_stiffness",
              "drilling_stiffness", "step_length", "hourglass_yield")  # fmt: skip
# The shells' [element] keys of the quadrilateral's kernel only (shell_quad.c).
QUADRILATERAL_KEYS = ("hourglass_stiffness", "drilling_stiffness", "step_length",
                      "hourglass_yield")  # fmt: skip
SOLID_KEYS = ("integration", "hourglass", "hourglass_coefficient")


@table("Element technology (LS-DYNA *SECTION_SOLID + *HOURGLASS, Radioss /PROP/SOLID); optional.")
@dataclass(frozen=True)
class Element:
    integration: str | None = key(
        Choice(("reduced", "full")),
        None,
        doc="reduced: one point + hourglass control (hexahedra only); full: 2x2x2 Gauss on "
        "hexahedra, one exact point on (P1) tetrahedra",
        default_doc="reduced on hexahedra, full on tetrahedra (None: by cell type)",
    )
    hourglass: str | None = key(
        Choice((*_HOURGLASS_FORMS, "none")),
        None,
        when={"integration": ("reduced",)},
        doc="physical: assumed-strain stabilisation (Belytschko-Bindeman, Radioss HEPH); "
        "stiffness, viscous: Flanagan-Belytschko forms; none",
        default_doc="physical",
    )
    hourglass_coefficient: float | None = key(
        Real(low=0.0),
        None,
        when={"integration": ("reduced",), "hourglass": _HOURGLASS_FORMS},
        doc="scales the hourglass forces",
        default_doc="physical: 1.0 (full integration on parallelepipeds) on elastic bodies, 0.1 "
        "on elasto-plastic ones (elastic hourglass stresses would stiffen the plastic flow); "
        "stiffness, viscous: 0.1 (LS-DYNA's QM)",
    )
    thickness: float | None = key(
        Real(low=0.0),
        None,
        unit="m",
        doc="shells: the thickness (constant)",
        default_doc="a built-in plate's size[2]; required for a mesh file of surfaces",
    )
    formulation: str | None = key(
        Choice(("bwc", "bt", "qeph", "bsc")),
        None,
        doc="shells: bwc, Belytschko-Lin-Tsay with the Belytschko-Wong-Chiang warping "
        "correction; bt, plain Belytschko-Lin-Tsay (quadrilaterals); qeph, bwc with "
        "Radioss's QEPH physical hourglass stiffness per mode (membrane, bending, "
        "transverse shear; Ishell 24; not with hourglass_stiffness); bsc, the "
        "Belytschko-Stolarski-Carpenter triangle",
        default_doc="bwc on quadrilaterals, bsc on triangles",
    )
    points: int | None = key(
        Integer(1, 10, why="Radioss's N"),
        None,
        doc="shells: integration points through the thickness (equally spaced, both surfaces "
        "included)",
        default_doc="5",
    )
    hourglass_coefficients: tuple[float, float, float] | None = key(
        Vector(kind="non_negative"),
        None,
        doc="shells: the viscous hourglass coefficients of the membrane, bending and "
        "rotation modes (Radioss's hm, hf, hr)",
        default_doc="[0.01, 0.01, 0.01]",
    )
    shear_factor: float | None = key(
        Real(low=0.0, high=1.0),
        None,
        doc="shells: the transverse shear factor",
        default_doc="5/6",
    )
    failed_share: float | None = key(
        Real(low=0.0, high=1.0),
        None,
        doc="shells with [material.failure]: the share of a cell's points through the "
        "thickness that must have failed for the cell to fail and erode (Radioss's "
        "P_thickfail)",
        default_doc="1 (every point)",
    )
    thickness_change: bool | None = key(
        Flag(),
        None,
        doc="shells: the thickness follows the membrane strain, plastic flow keeping the "
        "volume (Radioss's Ithick = 1); false: constant",
        default_doc="false",
    )
    hourglass_stiffness: float | None = key(
        Real(low=0.0, low_open=False, high=1.0),
        None,
        doc="quadrilateral shells: an elastic hourglass stiffness beside the viscous one, as "
        "a share of the fully integrated cell's (1: its in-plane bending, too stiff for "
        "cells of aspect 2; 0.5 passes the twisted beam)",
        default_doc="0 (viscous hourglass control only)",
    )
    drilling_stiffness: float | None = key(
        Real(low=0.0, low_open=False, high=0.1),
        None,
        doc="quadrilateral shells: drilling springs of stiffness a G t A per node, between "
        "each node's rotation about the cell's normal and the cell's in-plane spin (for "
        "slow or static problems on twisted meshes; at most 0.1, so that they never set "
        "the step)",
        default_doc="0 (no drilling stiffness; Radioss's Idrill = 1 reads as 0.01)",
    )
    step_length: str | None = key(
        Choice(("bt", "qeph")),
        None,
        doc="quadrilateral shells: the characteristic length of the stable step L_c / c. bt: "
        "Radioss's for its Belytschko-Tsay shells, max(A / longest diagonal, shortest side "
        "or diagonal); qeph: QEPH's (Ishell 24), from the half diagonals and the cell's "
        "shape (0.894 of a square's side), times sqrt(1 + dn^2) - dn of its numerical "
        "damping dn = 0.015",
        default_doc="bt (Radioss's Ishell 24 and 12 read as qeph)",
    )
    hourglass_yield: bool | None = key(
        Flag(),
        None,
        doc="quadrilateral shells with hourglass_stiffness or formulation qeph, "
        "elasto-plastic materials: the elastic hourglass forces yield as in Radioss's QEPH "
        "(Ishell 24): in a cell whose points flow, or whose mean stresses with the hourglass "
        "stresses reach the yield stress, the step's membrane increment is scaled by the "
        "mean E_t / E of its points and the bending one by at most 0.001 (docs/theory.md)",
        default_doc="false (elastic hourglass forces; a deck's Ishell 24 sets it with "
        "formulation qeph: docs/radioss.md)",
    )


@table("The initial state of the body.")
@dataclass(frozen=True)
class Initial:
    velocity: tuple[float, float, float] = key(
        Vector(), (0.0, 0.0, 0.0), unit="m/s", doc="uniform initial velocity"
    )


@table("A uniform body force; no [gravity]: none.")
@dataclass(frozen=True)
class Gravity:
    acceleration: tuple[float, float, float] = key(
        Vector(), unit="m/s^2", doc="on every node, e.g. [0, 0, -9.81]"
    )


# --- [[boundary]] ----------------------------------------------------------------


@table(
    "A prescribed velocity (zero: a clamp) of some components of a named node set. On a node"
    " also secondary to a wall it wins on those components (it acts after the walls; the run"
    " warns)."
)
@dataclass(frozen=True)
class BoundarySpec:
    group: str = key(Text("the name of a node set"), doc="a named face group of the mesh")
    velocity: tuple = key(
        Velocity(),
        (0.0, 0.0, 0.0),
        unit="m/s",
        doc="constant, or a history (linear between rows, held outside them)",
    )
    components: str = key(
        Letters(), "xyz", doc="the global components prescribed; the others stay free"
    )
    rotations: str | None = key(
        Letters(),
        None,
        doc="shells: the global components of the nodes' rotations held fixed (with "
        "components = 'xyz', rotations = 'xyz' clamps an edge)",
        default_doc="none: the rotations stay free (a simply supported edge)",
    )


# --- [[load]], [[added_mass]], [damping] ---------------------------------------------

LOAD_KEYS = {"force": ("force", "per"), "pressure": ("pressure",)}


@table(
    "An external load (Radioss /CLOAD, /PLOAD): a force on the nodes of a named node set, or"
    " a follower pressure on the outer faces of a named face group, times a factor of time;"
    " its work is booked in external_work.",
    variants=Variants("kind", LOAD_KEYS, common=("group", "history"), noun="a {} load"),
)
@dataclass(frozen=True)
class LoadSpec:
    kind: str = key(Choice(tuple(LOAD_KEYS)), doc="a nodal force, or a pressure on faces")
    group: tuple[str, ...] = key(NodeSets(), doc="a named face group of the mesh, or several")
    force: tuple[float, float, float] | None = key(
        Vector(), None, required=True, unit="N", doc="the force at factor 1 (see per)"
    )
    per: str = key(
        Choice(("node", "set")),
        "node",
        doc="node: on each node of the set (Radioss /CLOAD); set: the total, spread equally",
    )
    pressure: float | None = key(
        Real(), None, required=True, unit="Pa",
        doc="at factor 1, on the current faces; positive pushes into the body",
    )  # fmt: skip
    history: tuple | None = key(
        Factor(), None, doc="the factor f(t) of s: linear between rows, held outside them",
        default_doc="1 at all times",
    )  # fmt: skip


@table(
    "Mass added to the nodes of a named node set (Radioss /ADMAS): it moves with them, and"
    " the summary's mass, the momentum and the kinetic energy include it."
)
@dataclass(frozen=True)
class AddedMassSpec:
    group: tuple[str, ...] = key(NodeSets(), doc="a named face group of the mesh, or several")
    mass: float = key(Real(low=0.0), unit="kg", doc="on each node, or the total (see per)")
    per: str = key(
        Choice(("node", "set")),
        "node",
        doc="node: on each node of the set (/ADMAS type 0); set: the total, spread equally",
    )


@table(
    "Rayleigh damping (Radioss /DAMP): the forces -alpha m v - beta K0 v on the nodes of a"
    " node set (K0 the stiffness at rest); their work is booked as damping_work."
)
@dataclass(frozen=True)
class Damping:
    alpha: float = key(
        Real(low=0.0, low_open=False), 0.0, unit="1/s", doc="mass-proportional coefficient"
    )
    beta: float = key(
        Real(low=0.0, low_open=False), 0.0, unit="s", doc="stiffness-proportional coefficient"
    )
    group: tuple[str, ...] | None = key(
        NodeSets(), None, doc="the nodes damped: face groups", default_doc="every node"
    )


@rule(Damping)
def _damping_does_something(v, raw, fail):
    """alpha or beta is above 0."""
    if v["alpha"] == 0.0 and v["beta"] == 0.0:
        fail("alpha", "alpha and beta are both 0: give one above 0, or drop [damping]")


# --- [[wall]] ------------------------------------------------------------------------


@table("Which nodes a wall acts on; none given: every boundary node of the body.")
@dataclass(frozen=True)
class Secondary:
    """Which nodes a wall acts on; the default is every boundary node of the body."""

    search_distance: float | None = key(
        Real(low=0.0, low_open=False),
        None,
        unit="m",
        doc="only the nodes with 0 <= distance <= this at the start",
        default_doc="no limit",
    )
    add: tuple[str, ...] = key(Names(), (), doc="named node sets (gmsh physical groups) to include")
    parts: tuple[str, ...] = key(
        Names(), (), doc="the nodes of these parts (Radioss's grnd_ID of a /GRNOD/PART)"
    )
    exclude: tuple[str, ...] = key(Names(), (), doc="named node sets to leave out; exclusion wins")


@table("A moving wall: a main node of some mass, or a prescribed velocity.")
@dataclass(frozen=True, kw_only=True)
class Motion:
    """A main node of ``mass`` starting at ``velocity``, or a prescribed ``velocity`` history."""

    mass: float | None = key(
        Real(low=0.0),
        None,
        unit="kg",
        doc="the main node's mass (it moves under the contact forces)",
        default_doc="none: the velocity is prescribed",
    )
    velocity: tuple = key(
        Velocity(), unit="m/s", doc="initial (with mass) or prescribed, constant or a history"
    )
    held: str | None = key(
        Letters(),
        None,
        doc="with mass: the global components of the main node's velocity kept at their "
        "initial value (the main node of a half or quarter model on its symmetry planes)",
        default_doc="none: the main node moves freely",
    )

    @property
    def prescribed(self) -> bool:
        return self.mass is None


@rule(
    Motion,
    json=[
        {"if": {"required": ["mass"]}, "then": {"properties": {"velocity": Vector().json()}}},
        {"if": {"not": {"required": ["mass"]}}, "then": {"not": {"required": ["held"]}}},
    ],
)
def _table_without_mass(v, raw, fail):
    """A velocity history prescribes the motion: no mass with it; `held` needs a mass."""
    if v["mass"] is not None and isinstance(v["velocity"][0], tuple):
        fail("mass", "a velocity table prescribes the motion: drop 'mass'")
    if v["mass"] is None and v["held"] is not None:
        fail("held", "a prescribed velocity holds every component: give 'mass' or drop 'held'")


@table("The friction filter of Radioss: exactly one of its keys.", one_of=True)
@dataclass(frozen=True)
class FrictionFilter:
    coefficient: float | None = key(
        Real(low=0.0, high=1.0), None, doc="alpha, the weight of the new tangential force"
    )
    steps: float | None = key(
        Real(low=2 * math.pi, low_open=False), None, doc="the filter's period in steps"
    )
    frequency: float | None = key(Real(low=0.0), None, unit="Hz", doc="the cut-off frequency")


def _filter(f: FrictionFilter) -> tuple[str, float]:
    return next((name, x) for name, x in vars(f).items() if x is not None)


@table(
    "A rigid wall (Radioss /RWALL): its kind, shape points, sliding, nodes, motion.",
    variants=Variants("kind", SHAPE_KEYS, common=_WALL_KEYS, noun="a {} wall"),
)
@dataclass(frozen=True)
class WallSpec:
    kind: str = key(Choice(tuple(SHAPE_KEYS)), doc="the wall's shape")
    point: tuple[float, float, float] = key(
        Vector(), unit="m", doc="M: on the plane, on the axis, the centre, a corner"
    )
    normal_point: tuple[float, float, float] | None = key(
        Vector(), None, required=True, unit="m", doc="M1: the normal M1 - M points to the free side"
    )
    axis_point: tuple[float, float, float] | None = key(
        Vector(), None, required=True, unit="m", doc="M1: the axis M1 - M"
    )
    diameter: float | None = key(
        Real(low=0.0), None, required=True, unit="m", doc="contact from outside only"
    )
    corner1: tuple[float, float, float] | None = key(
        Vector(), None, required=True, unit="m", doc="M1: side L1 = M1 - M"
    )
    corner2: tuple[float, float, float] | None = key(
        Vector(), None, required=True, unit="m", doc="M2: side L2 = M2 - M; normal along L1 x L2"
    )
    slide: str = key(
        Choice(("free", "tied", "friction"), {0: "free", 1: "tied", 2: "friction"}),
        "free",
        doc="free: frictionless; tied: no sliding; friction: Coulomb",
    )
    friction: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        required=True,
        when={"slide": ("friction",)},
        doc="the Coulomb coefficient mu",
    )
    friction_filter: tuple[str, float] | None = key(
        Sub(FrictionFilter, then=_filter),
        None,
        when={"slide": ("friction",)},
        doc="(how, value): smooths the tangential force",
        default_doc="none",
    )
    secondary: Secondary = key(Sub(Secondary), factory=Secondary, doc="the nodes it acts on")
    motion: Motion | None = key(Sub(Motion), None, doc="how it moves", default_doc="fixed")


def _distinct(v, name, fail):
    point, other = v["point"], v[name]
    scale = max(math.hypot(*point), math.hypot(*other))
    if math.dist(point, other) <= 1e-10 * scale:
        fail(name, f"must differ from 'point' ({name} = point leaves no direction)")


@rule(WallSpec)
def _points_span_the_shape(v, raw, fail):
    """normal_point, axis_point, corner1 and corner2 differ from point, and the sides of a
    parallelogram are not parallel."""
    for name in SHAPE_KEYS[v["kind"]]:
        if name != "diameter":
            _distinct(v, name, fail)
    if v["kind"] == "parallelogram":
        l1 = [a - b for a, b in zip(v["corner1"], v["point"], strict=True)]
        l2 = [a - b for a, b in zip(v["corner2"], v["point"], strict=True)]
        cross = math.hypot(
            l1[1] * l2[2] - l1[2] * l2[1],
            l1[2] * l2[0] - l1[0] * l2[2],
            l1[0] * l2[1] - l1[1] * l2[0],
        )
        if cross <= 1e-10 * math.hypot(*l1) * math.hypot(*l2):
            fail("corner2", "sides corner1 - point and corner2 - point are parallel")


# --- [[contact]] ----------------------------------------------------------------------


@table(
    "A contact interface between parts (Radioss /INTER/TYPE7, LS-DYNA *CONTACT_AUTOMATIC_"
    "SURFACE_TO_SURFACE / _SINGLE_SURFACE): penalty forces between the boundary faces of "
    "solid parts, with a gap and Coulomb friction."
)
@dataclass(frozen=True)
class ContactSpec:
    main: tuple[str, ...] = key(
        Names(),
        (),
        doc="the parts whose boundary faces are the main segments (with self: the parts "
        "in contact with themselves)",
        default_doc="with self: every part",
    )
    secondary: tuple[str, ...] = key(
        Names(), (), doc="the parts whose boundary nodes are the secondary nodes (not with self)"
    )
    single_surface: bool = key(
        Flag(),
        False,
        toml="self",
        doc="self-contact of the main parts (a node against every segment but those that "
        "hold it, as Radioss's TYPE7)",
    )
    symmetric: bool = key(
        Flag(), True, doc="two passes: each side's nodes against the other's segments"
    )
    gap: float | None = key(
        Real(low=0.0),
        None,
        unit="m",
        doc="the contact distance (Radioss Gapmin), constant: forces act below it and stiffen "
        "toward it, k0 g / (g - p) at penetration p",
        default_doc="0.1 x the shortest edge of the segments; on shells a variable gap, half "
        "the sum of the thicknesses (Radioss Igap 1)",
    )
    gap_scale: float = key(
        Real(low=0.0),
        1.0,
        doc="Radioss Fscalegap: scales each shell's half thickness in the variable gap "
        "(before gap_size_share and gap_max)",
    )
    gap_max: float | None = key(
        Real(low=0.0),
        None,
        unit="m",
        doc="Radioss Gap_max: the variable gap of a pair (the sum of its two shares) at most "
        "this, never below the floor gap",
        default_doc="no bound",
    )
    gap_size_share: float = key(
        Real(low=0.0, high=1.0),
        0.4,
        doc="Radioss %mesh_size (Igap 3): a pair's variable gap at most this fraction of the "
        "sum of the shortest sides of the node's shells and of the segment",
    )
    exclude_within_gap: bool = key(
        Flag(),
        False,
        doc="Radioss Irem_gap 2: each segment leaves out of its search the nodes within "
        "sqrt(2) x their pair gap of it along the mesh, at the start (self-contact of a mesh "
        "finer than the gap; beyond a node's own segments)",
    )
    stiffness_scale: float = key(
        Real(low=0.0),
        1.0,
        doc="Radioss Stfac: scales the penalty stiffness k0 = B A^2 / V of the cell under "
        "each segment (E t of a shell segment)",
    )
    stiffness_min: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="N/m",
        doc="Radioss Stmin: the penalty stiffness k0 of each segment (after stiffness_scale) "
        "at least this",
    )
    stiffness_max: float | None = key(
        Real(low=0.0),
        None,
        unit="N/m",
        doc="Radioss Stmax: the penalty stiffness k0 of each segment (after stiffness_scale) "
        "at most this",
        default_doc="no bound",
    )
    damping: float = key(
        Real(low=0.0, low_open=False, high=1.0),
        0.05,
        doc="Radioss VISs: the normal damping of each pair, a fraction of its critical "
        "damping 2 sqrt(k m)",
    )
    friction: float = key(Real(low=0.0, low_open=False), 0.0, doc="the Coulomb coefficient mu")
    friction_filter: tuple[str, float] | None = key(
        Sub(FrictionFilter, then=_filter),
        None,
        doc="(how, value): smooths the friction force, as the walls' filter",
        default_doc="none",
    )


@rule(
    ContactSpec,
    json=[
        {
            "if": {"properties": {"self": {"const": True}}, "required": ["self"]},
            "then": {"properties": {"secondary": {"maxItems": 0}}},
            "else": {
                "required": ["main", "secondary"],
                "properties": {"main": {"minItems": 1}, "secondary": {"minItems": 1}},
            },
        }
    ],
)
def _sides_are_named(v, raw, fail):
    """Without self, main and secondary each name at least one part; with self, secondary
    is not given."""
    if v["single_surface"]:
        if v["secondary"]:
            fail("secondary", "self-contact has no secondary parts: name the parts in main")
        return
    for side in ("main", "secondary"):
        if not v[side]:
            fail(side, "names no part; give at least one part name (or self = true)")


# The keys that shape the variable gap only.
_VARIABLE_GAP_KEYS = ("gap_scale", "gap_max", "gap_size_share")


@rule(
    ContactSpec,
    json=[
        {
            "if": {"required": ["gap"]},
            "then": {"not": {"anyOf": [{"required": [k]} for k in _VARIABLE_GAP_KEYS]}},
        }
    ],
)
def _gap_keys_agree(v, raw, fail):
    """gap_scale, gap_max and gap_size_share shape the variable gap: not with a given
    (constant) gap; stiffness_min is not above stiffness_max."""
    if v["gap"] is not None:
        for name in _VARIABLE_GAP_KEYS:
            if name in raw:
                fail(name, "shapes the variable gap: leave it out with a given gap (constant), "
                     "or leave gap out")  # fmt: skip
    high = v["stiffness_max"]
    if high is not None and v["stiffness_min"] > high:
        fail("stiffness_min", f"{v['stiffness_min']:g} N/m is above stiffness_max {high:g} "
             "N/m: the bounds of the penalty stiffness")  # fmt: skip


# --- [[part]] -------------------------------------------------------------------------


@table(
    "A part of the body (Radioss /PART, LS-DYNA *PART): regions of the mesh with their "
    "material, element technology and initial velocity. Without [[part]] the whole body is "
    "one part of the scene's [material], [element] and [initial]."
)
@dataclass(frozen=True)
class PartSpec:
    name: str = key(
        Identifier("a part name"),
        doc="how outputs and walls (secondary.parts) call it; unique in the scene",
    )
    volumes: tuple[str, ...] = key(
        Names(),
        (),
        doc="the regions it is made of: named gmsh physical volumes (a built-in shape's "
        "'body', 'front', 'bottom_layer', 'top_layer')",
        default_doc="[name]",
    )
    material: Material | None = key(
        Sub(Material), None, doc="its material", default_doc="the scene's [material]"
    )
    element: Element | None = key(
        Sub(Element), None, doc="its element technology", default_doc="the scene's [element]"
    )
    initial: Initial | None = key(
        Sub(Initial), None, doc="its initial velocity", default_doc="the scene's [initial]"
    )


@rule(PartSpec)
def _volumes_default_to_the_name(v, raw, fail):
    """volumes defaults to [name]."""
    if not v["volumes"]:
        v["volumes"] = (v["name"],)


# --- [output] -----------------------------------------------------------------------


@table("What a run writes besides summary.json, energy.csv and walls.csv.")
@dataclass(frozen=True)
class Output:
    directory: Path = key(
        Text("a path string", path=True),
        Path("results"),
        doc="the results folder (--out overrides it)",
    )
    frames: int = key(
        Integer(low=0), 0, doc="PNG frames over the run, and animation.gif; 0: no pictures"
    )
    fields: int = key(
        Integer(low=0), 0, doc="snapshots of displacement, velocity, von Mises in fields.xdmf"
    )
    history_interval: int = key(
        Integer(low=1),
        1,
        doc="steps between rows of energy.csv, walls.csv and contacts.csv (and the first and "
        "last steps)",
    )
    history_time: float | None = key(
        Real(low=0.0),
        None,
        unit="s",
        doc="time between rows of energy.csv, walls.csv and contacts.csv instead: a row at "
        "the first step at or after each multiple of it, and at the first and last steps "
        "(Radioss /TFILE, LS-DYNA *DATABASE_GLSTAT)",
        default_doc="rows by history_interval",
    )
    print_interval: int | None = key(
        Integer(low=1),
        None,
        doc="steps between cycle lines (cycle, time, dt, energy error, elapsed) in run.log, "
        "and on stderr when it is not a terminal",
        default_doc="about 20 lines over the run",
    )
    color: str = key(
        Choice(("normal_velocity", "speed", "displacement", "plastic_strain", "damage", "part",
                "contact_pressure")),
        "normal_velocity",
        doc="what colours the frames (plastic_strain: elasto-plastic bodies; damage: bodies "
        "with a failure criterion; part: a body of [[part]], one colour each; "
        "contact_pressure: a scene with [[contact]], Pa)",
    )
    view: ViewSpec | None = key(
        Sub(ViewSpec),
        None,
        doc="how the frames look at the body: a cut, the camera, the picture size, the colour "
        "range",
        default_doc="the whole body, from the camera chosen automatically",
    )
    plot: bool = key(Flag(), True, doc="histories.png: energies and wall forces over time")
    checkpoint_steps: int = key(
        Integer(low=0),
        0,
        doc="steps between checkpoints (directory/checkpoint, for run --resume); 0: none",
    )
    checkpoint_seconds: float = key(
        Real(low=0.0, low_open=False),
        0.0,
        unit="s",
        doc="wall time between checkpoints, at least 1 s; 0: none (a stop by SIGTERM or a "
        "guard writes one)",
    )
    units: str = key(
        Text("a unit system"),
        "SI",
        doc="the units of energy.csv, walls.csv and summary.json: SI, or a system of mass, "
        "length and time as codes ('kg-mm-ms', 'Mg-mm-s') or sizes in SI ('1000 0.001 1'); "
        "'deck': the work units of a Radioss deck's /BEGIN",
    )


@rule(Output)
def _output_units(v, raw, fail):
    """units is SI, or a unit system of three codes or sizes ('deck' is resolved when a
    Radioss deck is read)."""
    if v["units"] == "deck":
        fail("units", "'deck' is for a scene read from a Radioss deck (the work units of its "
             "/BEGIN); give the units, e.g. 'kg-mm-ms'")  # fmt: skip
    try:
        parse_system(v["units"])
    except ValueError as err:
        fail("units", f"{show(v['units'])}: {err}")


@rule(Output, json=[{"not": {"required": ["history_interval", "history_time"]}}])
def _one_history_interval(v, raw, fail):
    """history_interval (steps) and history_time (s) are two ways to space the rows of
    the histories: one of them."""
    if "history_interval" in raw and "history_time" in raw:
        fail("history_time", "give history_interval (steps) or history_time (s) between "
             "history rows, not both")  # fmt: skip


# Checkpoints are large files written and synced by every rank: a wall-time interval
# shorter than this would write one at nearly every step (as Radioss's /RFILE and
# LS-DYNA's d3dump count in cycles, output.checkpoint_steps is the way to go finer).
MIN_CHECKPOINT_SECONDS = 1.0


@rule(
    Output,
    json=[
        {
            "properties": {
                "checkpoint_seconds": {"anyOf": [{"const": 0}, {"minimum": MIN_CHECKPOINT_SECONDS}]}
            }
        }
    ],
)
def _checkpoints_are_not_every_step(v, raw, fail):
    """checkpoint_seconds is 0 (none) or at least 1 s: every checkpoint writes and syncs a
    file per rank, and a shorter interval would write one at nearly every step."""
    seconds = v["checkpoint_seconds"]
    if 0.0 < seconds < MIN_CHECKPOINT_SECONDS:
        fail(
            "checkpoint_seconds",
            f"{seconds:g} s would write and sync a checkpoint at nearly every step; give 0 "
            f"(none) or at least {MIN_CHECKPOINT_SECONDS:g} s, or output.checkpoint_steps for "
            "checkpoints every so many steps",
        )


# --- the scene -----------------------------------------------------------------------


@table("A scene: one body, its material, walls and boundary conditions, and what to write.")
@dataclass(frozen=True, kw_only=True)
class Scene:
    source: str  # the file name used in messages
    run: RunSettings = key(Sub(RunSettings), doc="time span and step")
    mesh: MeshSpec | None = key(
        Sub(MeshSpec, empty_is_none=True),
        None,
        doc="the body",
        default_doc="a body given to the API",
    )
    pieces: tuple[PieceSpec, ...] = key(
        Each(PieceSpec),
        (),
        toml="piece",
        doc="the body as separate pieces of built-in shapes, instead of [mesh]",
        default_doc="none: the body of [mesh]",
    )
    material: Material | None = key(
        Sub(Material),
        None,
        doc="the body's material (with [[part]]: of the parts that give none)",
        default_doc="required without [[part]]",
    )
    element: Element = key(Sub(Element), factory=Element, doc="element technology")
    initial: Initial = key(Sub(Initial), factory=Initial, doc="the initial velocity")
    gravity: tuple[float, float, float] | None = key(
        Sub(Gravity, then=lambda g: g.acceleration),
        None,
        doc="the acceleration of gravity (m/s^2)",
        default_doc="none",
    )
    boundaries: tuple[BoundarySpec, ...] = key(
        Each(BoundarySpec), (), toml="boundary", doc="prescribed velocities of node sets"
    )
    walls: tuple[WallSpec, ...] = key(Each(WallSpec), (), toml="wall", doc="the rigid walls")
    loads: tuple[LoadSpec, ...] = key(
        Each(LoadSpec), (), toml="load", doc="nodal forces and pressures", default_doc="none"
    )
    added_masses: tuple[AddedMassSpec, ...] = key(
        Each(AddedMassSpec), (), toml="added_mass", doc="masses added to node sets",
        default_doc="none",
    )  # fmt: skip
    damping: Damping | None = key(
        Sub(Damping), None, doc="Rayleigh damping", default_doc="none"
    )
    contacts: tuple[ContactSpec, ...] = key(
        Each(ContactSpec), (), toml="contact", doc="contact interfaces between parts"
    )
    parts: tuple[PartSpec, ...] = key(
        Each(PartSpec), (), toml="part", doc="the parts of the body", default_doc="one: the body"
    )
    rigid_bodies: tuple[RigidBodySpec, ...] = key(
        Each(RigidBodySpec), (), toml="rigid_body", doc="node sets that move as rigid bodies"
    )
    output: Output = key(Sub(Output), factory=Output, doc="pictures, fields, histories")

    @property
    def body_parts(self) -> tuple[PartSpec, ...]:
        """The parts with the scene's defaults filled in; without [[part]], one part named
        "body" of every cell (``volumes`` empty)."""
        if not self.parts:
            return (PartSpec("body", (), self.material, self.element, self.initial),)
        return tuple(
            PartSpec(
                p.name,
                p.volumes,
                p.material or self.material,
                p.element or self.element,
                p.initial or self.initial,
            )
            for p in self.parts
        )


_TETRAHEDRA = {
    "properties": {
        "mesh": {"properties": {"cell": {"const": "tetrahedron"}}, "required": ["cell"]}
    },
    "required": ["mesh"],
}
_FULL_ONLY = {
    "properties": {
        "integration": {"not": {"const": "reduced"}},
        "hourglass": False,
        "hourglass_coefficient": False,
    }
}


@rule(
    Scene,
    json=[
        {"if": _TETRAHEDRA, "then": {"properties": {"element": _FULL_ONLY}}},
        {
            "if": _TETRAHEDRA,
            "then": {"properties": {"part": {"items": {"properties": {"element": _FULL_ONLY}}}}},
        },
    ],
)
def _element_fits_the_cells(v, raw, fail):
    """Tetrahedra (mesh.cell) are P1, integrated exactly at one point: "full" only, and no
    hourglass keys, in [element] and in every part's. (For a mesh file the cell type is
    checked when the body is built.)"""
    mesh = v["mesh"]
    if mesh is None or mesh.shape is None or mesh.cell != "tetrahedron":
        return
    tables = [("element", v["element"], raw.get("element", {}))]
    for i, part in enumerate(v["parts"]):
        if part.element is not None:
            tables.append((f"part[{i}].element", part.element, raw["part"][i]["element"]))
    for where, element, given in tables:
        if element.integration == "reduced":
            fail(
                f"{where}.integration",
                "'reduced' is for hexahedra, and mesh.cell is 'tetrahedron' (P1, one exact "
                "point): use 'full' or leave it out",
            )
        for name in ("hourglass", "hourglass_coefficient"):
            if element.integration is None and name in given:
                fail(
                    f"{where}.{name}",
                    "needs integration = 'reduced', and tetrahedra (mesh.cell) are integrated "
                    "'full'",
                )


def element_tables(v, raw) -> list[tuple[str, Element, dict]]:
    """(where, the table, its raw keys) of [element] and of every part's own."""
    tables = [("element", v["element"], raw.get("element", {}))]
    for i, part in enumerate(v["parts"]):
        if part.element is not None:
            tables.append((f"part[{i}].element", part.element, raw["part"][i]["element"]))
    return tables


def element_fits_the_surface(where: str, given, cell: str) -> str | None:
    """What is wrong, in one line naming the key, with an element table whose keys are
    ``given`` for ``cell`` cells (a shell's or a solid's), or None."""
    shells = cell in SURFACE_CELLS
    for name in SOLID_KEYS if shells else SHELL_KEYS:
        if name in given:
            what = "solids (hexahedra, tetrahedra)" if shells else "shells (surface cells)"
            return f"{where}.{name}: is for {what}, and the mesh has {cell} cells: leave it out"
    if cell == "triangle":
        for name in QUADRILATERAL_KEYS:
            if name in given:
                return (f"{where}.{name}: is for quadrilateral shells (the triangle has no "
                        "such term), and the mesh has triangle cells: leave it out")  # fmt: skip
    formulation = given.get("formulation")
    fits = {"quadrilateral": ("bt", "bwc", "qeph"), "triangle": ("bsc",)}
    if shells and formulation is not None and formulation not in fits[cell]:
        return (f"{where}.formulation: {formulation!r} is not an element of {cell} cells; "
                f"allowed: {', '.join(fits[cell])}")  # fmt: skip
    return None


@rule(Scene, json=[{"not": {"required": ["mesh", "piece"]}}])
def _pieces_instead_of_mesh(v, raw, fail):
    """[[piece]] stands instead of [mesh]; the pieces have unique names and one cell type."""
    pieces = v["pieces"]
    if not pieces:
        return
    if v["mesh"] is not None:
        fail("piece", "give either [mesh] or [[piece]], not both (the pieces are the body)")
    names: dict[str, int] = {}
    for i, piece in enumerate(pieces):
        if piece.name in names:
            fail(f"piece[{i}].name",
                 f"{piece.name!r} is also the name of piece[{names[piece.name]}]")  # fmt: skip
        names[piece.name] = i
        if piece.cell != pieces[0].cell:
            fail(f"piece[{i}].cell", f"{piece.cell!r}, and piece[0] is {pieces[0].cell!r}: a "
                 "body has one cell type")  # fmt: skip


@rule(Scene)
def _element_fits_shells_or_solids(v, raw, fail):
    """Shell keys (thickness, formulation, points, hourglass_coefficients, shear_factor, ...)
    for surface cells only, the solids' (integration, hourglass, hourglass_coefficient) for
    volume cells only; formulation bt, bwc or qeph on quadrilaterals, bsc on triangles;
    hourglass_stiffness, drilling_stiffness and step_length on quadrilaterals only. (For a
    mesh file the cells are known when the body is built.)"""
    mesh = v["mesh"]
    if mesh is None or mesh.shape is None:
        return
    for where, _, given in element_tables(v, raw):
        wrong = element_fits_the_surface(where, given, mesh.cell)
        if wrong:
            name, _, why = wrong.partition(": ")
            fail(name, why)


@rule(
    Scene,
    json=[
        {"if": {"not": {"required": ["part"]}}, "then": {"required": ["material"]}},
        {
            "if": {"not": {"required": ["material"]}},
            "then": {"properties": {"part": {"items": {"required": ["material"]}}}},
        },
    ],
)
def _parts_are_whole(v, raw, fail):
    """Without [[part]], [material] is required; with it, every part has a material (its
    own or [material]), the parts' names are unique, no region is in two parts, and a
    wall's secondary.parts names parts."""
    parts = v["parts"]
    if not parts and v["material"] is None:
        fail("material", "missing")
    names: dict[str, int] = {}
    regions: dict[str, int] = {}
    for i, part in enumerate(parts):
        if part.material is None and v["material"] is None:
            fail(f"part[{i}].material", "missing: give it, or a [material] for the parts "
                 "that give none")  # fmt: skip
        if part.name in names:
            fail(f"part[{i}].name", f"{part.name!r} is also the name of part[{names[part.name]}]")
        names[part.name] = i
        for region in part.volumes:
            if region in regions:
                fail(
                    f"part[{i}].volumes",
                    f"the region {region!r} is also in part[{regions[region]}]: a cell is in "
                    "one part only",
                )
            regions[region] = i
    known = list(names) or ["body"]
    for i, wall in enumerate(v["walls"]):
        for name in wall.secondary.parts:
            if name not in known:
                fail(
                    f"wall[{i}].secondary.parts",
                    f"unknown part {name!r}{did_you_mean(name, known)}; the parts: "
                    + ", ".join(known),
                )
