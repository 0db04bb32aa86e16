"""``--set key.path=value``: one change to the raw TOML of a scene before it is checked."""

from __future__ import annotations

import re
import tomllib
from typing import Any

from rwall_fem.scene.keys import SceneError

__all__ = ["apply_override"]

_WORD = re.compile(r"([A-Za-z0-9_-]+)((?:\[\d+\])*)")


def apply_override(raw: dict, item: str, source: str = "--set") -> None:
    """Apply ``key.path=value`` (``wall[0].slide="tied"``) to the raw scene, in place.

    The value is read as a TOML value; a bare word that is not one is taken as a string.
    Tables on the way are made when missing; array elements must exist.
    """
    key, sep, text = item.partition("=")
    key = key.strip()

    def fail(message: str):
        raise SceneError(f"{source}: --set {key if key.isprintable() else repr(key)}: {message}")

    if not sep or not key:
        raise SceneError(f"{source}: --set {item!r}: expected key.path=value")
    parts: list[str | int] = []
    for word in key.split("."):
        match = _WORD.fullmatch(word)
        if not match:
            fail("expected a key path like wall[0].slide (names, [index], dots)")
        parts.append(match[1])
        parts.extend(int(i) for i in re.findall(r"\d+", match[2]))

    node: Any = raw
    where = ""
    for part, after in zip(parts, [*parts[1:], None], strict=True):
        if isinstance(part, int):
            if not isinstance(node, list):
                fail(f"{where} is {_kind(node)}, not an array")
            if part >= len(node):
                fail(f"index {part} does not exist ({where} has {len(node)})")
            where = f"{where}[{part}]"
        else:
            if isinstance(node, list):
                fail(
                    f"{where} is an array: write {where}[{part}]"
                    if part.isdigit()
                    else f"{where} is an array of tables: index it, as in {where}[0].{part}"
                )
            if not isinstance(node, dict):
                fail(f"{where} is {_kind(node)}, not a table")
            if after is not None and part not in node:
                node[part] = [] if isinstance(after, int) else {}
            where = f"{where}.{part}" if where else part
        if after is None:
            node[part] = _value(text)
        else:
            node = node[part]


def _value(text: str) -> Any:
    try:
        parsed = tomllib.loads(f"v = {text}")
    except (tomllib.TOMLDecodeError, ValueError, RecursionError):
        return text.strip()
    return parsed["v"] if list(parsed) == ["v"] else text.strip()


def _kind(value: Any) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return "a date or time"
