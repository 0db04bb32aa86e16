"""Reading a scene: the file (UTF-8 TOML), the ``--set`` overrides, then the schema."""

from __future__ import annotations

import codecs
import os
import stat
import tomllib
from pathlib import Path
from typing import Any

from rwall_fem.scene.keys import Context, SceneError, read_table, show
from rwall_fem.scene.overrides import apply_override
from rwall_fem.scene.schema import Scene

__all__ = ["MAX_SCENE_BYTES", "load_scene", "parse_scene", "read_toml"]

MAX_SCENE_BYTES = 16 * 2**20  # a scene is text of a few kB; its mesh is a file of its own


def load_scene(path: str | Path, overrides: list[str] = ()) -> Scene:
    """Read, override (``key.path=value``) and validate the scene file at ``path``."""
    path = Path(path)
    raw = read_toml(path)
    for item in overrides:
        apply_override(raw, item, str(path))
    return parse_scene(raw, source=str(path), base=path.parent)


def read_toml(path: Path) -> dict:
    """The TOML mapping in the file ``path``; a UTF-8 byte-order mark is skipped. Only a
    regular file of at most ``MAX_SCENE_BYTES`` is read: a pipe would wait for a writer
    for ever, a device such as /dev/zero would never end."""
    try:
        info = os.stat(path)  # before opening: opening a pipe waits for a writer
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError
        if not stat.S_ISREG(info.st_mode):
            raise SceneError(f"{path}: not a scene file (a device or a pipe, not a file)")
        if info.st_size > MAX_SCENE_BYTES:
            raise SceneError(
                f"{path}: {info.st_size} bytes, more than a scene file's "
                f"{MAX_SCENE_BYTES // 2**20} MiB: not a scene file"
            )
        data = path.read_bytes()
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError):
        raise SceneError(f"{path}: scene file not found") from None
    except OSError as err:
        raise SceneError(f"{path}: cannot read the scene file: {err.strerror}") from None
    data = data.removeprefix(codecs.BOM_UTF8)
    try:
        if b"\0" in data:
            raise UnicodeDecodeError("utf-8", data, data.index(b"\0"), len(data), "NUL")
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SceneError(
            f"{path}: not a text file (binary data at byte {err.start}); a scene is UTF-8 TOML"
        ) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"{path}: not valid TOML: {' '.join(str(err).split())}") from None
    except ValueError as err:  # an integer beyond Python's digit limit
        reason = str(err).partition(";")[0]
        raise SceneError(f"{path}: not valid TOML: a number too long to read ({reason})") from None
    except RecursionError:
        raise SceneError(f"{path}: not valid TOML: arrays or tables nested too deeply") from None


def parse_scene(raw: dict, source: str = "<scene>", base: Path = Path(".")) -> Scene:
    """Validate the raw TOML mapping ``raw`` into a :class:`Scene`.

    From Python, a wall may also be a shape object (``PlaneWall(...)``), alone or as the key
    ``shape`` beside the wall's other keys; it is checked as the table it stands for.
    """
    ctx = Context(source, Path(base))
    if isinstance(raw, dict) and isinstance(raw.get("wall"), (list, tuple)):
        walls = [_shape_table(w, f"wall[{i}]", ctx) for i, w in enumerate(raw["wall"])]
        raw = raw | {"wall": walls}
    return read_table(Scene, raw, ctx, extra={"source": source})


def _is_shape(value: Any) -> bool:
    return hasattr(value, "kind") and hasattr(value, "parameters")


def _shape_table(raw: Any, path: str, ctx: Context) -> Any:
    """A wall given with a shape object (the Python API) as the table a scene file has."""
    if _is_shape(raw):
        return {"kind": raw.kind, **raw.parameters()}
    if not isinstance(raw, dict) or "shape" not in raw:
        return raw
    shape = raw["shape"]
    if not _is_shape(shape):
        ctx.fail(
            f"{path}.shape",
            "must be a wall shape: PlaneWall, CylinderWall, SphereWall or ParallelogramWall, "
            f"got {show(shape)}",
        )
    if "kind" in raw:
        ctx.fail(f"{path}.kind", "give either 'kind' or 'shape', not both")
    rest = {key: value for key, value in raw.items() if key != "shape"}
    return {"kind": shape.kind, **shape.parameters(), **rest}
