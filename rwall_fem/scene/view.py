"""The keys of ``[output.view]``: how the frames look at the body (cut, camera, size, range).

The scene reads them as the table ``output.view``; ``rwall-fem render DIR --view TEXT``
reads the same keys from a TOML inline table (``'cut = "y", zoom = 1.5'``), so that a
finished run's frames can be drawn again with another view. This module needs neither
DOLFINx nor VTK: the renderer imports it.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from rwall_fem.scene.keys import (
    Context,
    Flag,
    Invalid,
    Real,
    SceneError,
    ValueType,
    _is_number,
    key,
    read_table,
    show,
    table,
)

__all__ = ["ViewSpec", "check_view", "parse_view_text", "read_view", "view_from_json",
           "view_to_json"]

AXES = ("x", "y", "z")
SIZES = (64, 4096)  # pixels: the least and largest side of a picture


def _finite(value) -> bool:
    return _is_number(value) and math.isfinite(float(value))


@dataclass(frozen=True)
class Cut(ValueType):
    """A clipping plane: "x", "y" or "z" (through the body's centre, normal along that
    axis), or a table {point = [x, y, z], normal = [x, y, z]}."""

    type_text = '"x", "y", "z" or {point, normal}'

    def read(self, value, ctx):
        if isinstance(value, str) and value in AXES:
            return value
        if isinstance(value, dict):
            extra = sorted(set(map(str, value)) - {"point", "normal"})
            point, normal = value.get("point"), value.get("normal")
            good = (
                not extra
                and all(isinstance(p, (list, tuple)) and len(p) == 3 for p in (point, normal))
                and all(_finite(c) for c in (*point, *normal))
                and any(float(c) != 0.0 for c in normal)
            )
            if good:
                return {"point": tuple(map(float, point)), "normal": tuple(map(float, normal))}
        raise Invalid(
            'must be "x", "y", "z" (through the body\'s centre) or a table {point = [x, y, z], '
            f"normal = [x, y, z]}} of finite numbers, the normal not all 0; got {show(value)}"
        )

    def allowed_text(self):
        return '"x", "y", "z"; or point and normal finite, normal not all 0'

    def json(self):
        vector = {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}
        plane = {
            "type": "object",
            "properties": {"point": vector, "normal": {**vector, "not": {"items": {"const": 0}}}},
            "required": ["point", "normal"],
            "additionalProperties": False,
        }
        return {"anyOf": [{"enum": list(AXES)}, plane]}


@dataclass(frozen=True)
class Focus(ValueType):
    """A point [x, y, z] (m) or the name of a part of the body."""

    type_text = "[x, y, z] or a part name"

    def read(self, value, ctx):
        if isinstance(value, str) and value:
            return value
        if isinstance(value, (list, tuple)) and len(value) == 3 and all(map(_finite, value)):
            return tuple(map(float, value))
        raise Invalid(f"must be a point [x, y, z] of finite numbers or a part name, got "
                      f"{show(value)}")  # fmt: skip

    def allowed_text(self):
        return "finite; a part of the body"

    def json(self):
        vector = {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}
        return {"anyOf": [vector, {"type": "string", "minLength": 1}]}


@dataclass(frozen=True)
class Size(ValueType):
    """A picture size [width, height] in pixels."""

    type_text = "[w, h]"

    def read(self, value, ctx):
        low, high = SIZES
        if (
            isinstance(value, (list, tuple))
            and len(value) == 2
            and all(type(v) is int and low <= v <= high for v in value)
        ):
            return tuple(value)
        raise Invalid(f"must be [width, height], integers in [{low}, {high}] (pixels), got "
                      f"{show(value)}")  # fmt: skip

    def allowed_text(self):
        return f"integers in [{SIZES[0]}, {SIZES[1]}]"

    def json(self):
        item = {"type": "integer", "minimum": SIZES[0], "maximum": SIZES[1]}
        return {"type": "array", "items": item, "minItems": 2, "maxItems": 2}


@dataclass(frozen=True)
class ColourRange(ValueType):
    """"auto" (one range for the whole run, from every frame) or [low, high]."""

    type_text = '"auto" or [low, high]'

    def read(self, value, ctx):
        if value == "auto":
            return value
        if (
            isinstance(value, (list, tuple))
            and len(value) == 2
            and all(map(_finite, value))
            and float(value[0]) < float(value[1])
        ):
            return tuple(map(float, value))
        raise Invalid(f'must be "auto" or [low, high] with low < high, finite, in the unit of '
                      f"the colour bar; got {show(value)}")  # fmt: skip

    def allowed_text(self):
        return '"auto"; or low < high, finite'

    def json(self):
        pair = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}
        return {"anyOf": [{"const": "auto"}, pair]}


@table(
    "How the frames look at the body. No [output.view]: the whole body, uncut, from the "
    "camera rwall_fem chooses (docs/outputs.md, Frames)."
)
@dataclass(frozen=True)
class ViewSpec:
    cut: Any = key(
        Cut(),
        None,
        doc='a clipping plane: "x", "y" or "z" through the centre of the body\'s box at the '
        "start, or {point, normal} (m): the half the normal points to is removed, the field "
        "shows on the cut face, and the camera looks at it",
        default_doc="no cut",
    )
    ghost: bool = key(Flag(), False, doc="draw the half a cut removes, translucent")
    zoom: float = key(
        Real(low=0.0, high=100.0), 1.0, doc="magnification of the fitted view (2: half the width)"
    )
    focus: Any = key(
        Focus(),
        None,
        unit="m",
        doc="the point at the picture's centre, or a part whose centre at the start is",
        default_doc="the centre of the body's extent over the run",
    )
    azimuth: float | None = key(
        Real(low=-360.0, high=360.0),
        None,
        unit="degree",
        doc="the camera's turn round the up direction, from the direction chosen automatically",
        default_doc="0",
    )
    elevation: float | None = key(
        Real(low=-90.0, high=90.0, low_open=False),
        None,
        unit="degree",
        doc="the camera's height above the horizontal plane (normal to up)",
        default_doc="chosen automatically (20, 30 over a plate)",
    )
    size: tuple = key(Size(), (800, 600), doc="the pictures' [width, height] in pixels")
    range: Any = key(
        ColourRange(),
        "auto",
        doc='the colour range, the same in every frame: "auto" (from every frame of the run) '
        "or [low, high] in the colour bar's unit",
    )


def read_view(raw: Any, source: str, path: str = "output.view") -> ViewSpec:
    """The view of the raw table ``raw``; SceneError (one line, ``source: path.key: ...``)."""
    return read_table(ViewSpec, raw, Context(source, Path("."), path))


def parse_view_text(text: str) -> ViewSpec:
    """The view of ``--view TEXT``: the keys of [output.view] as a TOML inline table's inside
    (``cut = "y", zoom = 2``); SceneError (one line) when it is not."""
    try:
        raw = tomllib.loads(f"view = {{{text}}}")["view"]
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"--view: not a TOML inline table's keys ({err}): {text!r}") from None
    return read_view(raw, "--view", "")


def view_to_json(view: ViewSpec) -> dict:
    """``view`` as JSON-able values (stored with the frame data; keys left to the automatic
    choice are left out, as in TOML)."""
    return {k: v for k, v in asdict(view).items() if v is not None}


def view_from_json(raw: dict, source: str) -> ViewSpec:
    """The view stored by :func:`view_to_json`."""
    return read_view(raw, source, "view")


def check_view(view: ViewSpec, X, parts, source: str, comm) -> None:
    """What ``view`` asks of the body: a focus part it has (``parts``, the names; empty
    for a body without [[part]]), a cut plane that meets its box (``X``, the owned nodes'
    reference coordinates on each rank of ``comm``, m). SceneError (one line) otherwise."""
    import numpy as np
    from mpi4py import MPI

    if isinstance(view.focus, str) and view.focus not in parts:
        have = f"its parts: {', '.join(parts)}" if parts else "a body without [[part]]"
        raise SceneError(f"{source}: output.view.focus: {view.focus!r} is not a part of this "
                         f"body ({have}); give a part or a point [x, y, z]")  # fmt: skip
    if isinstance(view.cut, dict):
        point, normal = np.array(view.cut["point"]), np.array(view.cut["normal"])
        side = (np.asarray(X) - point) @ (normal / np.linalg.norm(normal))
        low = comm.allreduce(float(side.min(initial=np.inf)), op=MPI.MIN)
        high = comm.allreduce(float(side.max(initial=-np.inf)), op=MPI.MAX)
        if not low < 0.0 < high:
            raise SceneError(
                f"{source}: output.view.cut: the plane through {list(view.cut['point'])} "
                f"normal to {list(view.cut['normal'])} does not cut the body (all its nodes "
                "lie on one side at the start); give a plane through it"
            )
