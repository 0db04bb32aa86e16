"""A raw scene table written as TOML text: the keys and values a scene file holds."""

from __future__ import annotations

import json
import math

__all__ = ["toml_text"]


def _value(v) -> str:
    if hasattr(v, "item") and not isinstance(v, (list, tuple, dict)):
        v = v.item()  # a NumPy scalar: its repr is not TOML
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"not a finite number: {v}")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"no TOML for {type(v).__name__}")


def toml_text(raw: dict, header: str = "") -> str:
    """``raw`` as TOML: scalars first, then tables (``[a]``, ``[a.b]``) and arrays of
    tables (``[[part]]``, their own tables after them: ``[part.material]``); ``header``:
    comment lines."""
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]

    def table(name: str, content: dict) -> None:
        scalars = {k: v for k, v in content.items() if not isinstance(v, dict)}
        lines.append(f"\n[{name}]")
        lines.extend(f"{k} = {_value(v)}" for k, v in scalars.items())
        for k, v in content.items():
            if isinstance(v, dict):
                table(f"{name}.{k}", v)

    for key, value in raw.items():
        if not isinstance(value, (dict, list)) or (isinstance(value, list) and value and
                                                    not isinstance(value[0], dict)):  # fmt: skip
            lines.append(f"{key} = {_value(value)}")
    for key, value in raw.items():
        if isinstance(value, dict):
            table(key, value)
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for item in value:
                lines.append(f"\n[[{key}]]")
                lines.extend(f"{k} = {_value(v)}" for k, v in item.items()
                             if not isinstance(v, dict))  # fmt: skip
                for k, v in item.items():
                    if isinstance(v, dict):
                        table(f"{key}.{k}", v)
    return "\n".join(lines).lstrip("\n") + "\n"
