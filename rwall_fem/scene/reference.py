"""The reference page and the JSON Schema of the scene format, both from the schema.

``python -m rwall_fem.scene.reference`` writes ``docs/reference/scene.md`` and
``rwall_fem/scene/scene.schema.json``; a test checks that the committed files
are what it would write.

The JSON Schema (draft 2020-12) lets a TOML editor complete and check scene
files: types, ranges, choices, unknown keys, the keys of each wall kind and mesh
shape, keys that need another key's value. Rules that compare numbers across
keys (a hole that fits its plate, a refinement near the body) are beyond it:
``rwall-fem check`` applies them all.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from rwall_fem.scene.keys import Choice, Each, Key, Sub, keys_of
from rwall_fem.scene.schema import Scene

__all__ = ["SCHEMA_FILE", "json_schema", "reference_page", "tables", "write"]

SCHEMA_FILE = Path(__file__).with_name("scene.schema.json")
PAGE = Path("docs/reference/scene.md")  # relative to the repository


# --- JSON Schema ----------------------------------------------------------------


def json_schema() -> dict:
    """The JSON Schema (draft 2020-12) of a scene file."""
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "rwall_fem scene",
        **_table_schema(Scene),
    }


def _json_default(value):
    if isinstance(value, tuple):
        return [_json_default(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    return value


def _key_schema(f: dataclasses.Field, k: Key) -> dict:
    if isinstance(k.type, Sub):
        out = _table_schema(k.type.cls)
    elif isinstance(k.type, Each):
        out = {"type": "array", "items": _table_schema(k.type.cls)}
    else:
        out = k.type.json()
    unit = f" ({k.unit})" if k.unit else ""
    out = {"description": f"{k.doc}{unit}", **out}
    if k.default_doc is None and f.default not in (dataclasses.MISSING, None):
        out["default"] = _json_default(f.default)
    return out


def _table_schema(cls) -> dict:
    spec = cls.__table__
    keys = keys_of(cls)
    names = {f.name: name for name, (f, _) in keys.items()}  # field -> TOML name
    out: dict = {
        "type": "object",
        "description": spec.doc,
        "properties": {name: _key_schema(f, k) for name, (f, k) in keys.items()},
        "additionalProperties": False,
    }
    rules: list[dict] = []
    variable: set[str] = set()  # keys required only in some variants
    if v := spec.variants:
        variable = {n for names_ in v.cases.values() for n in names_} - set(v.common)
        for case, own in v.cases.items():
            allowed = {v.on, *own, *v.common}
            rules.append(
                {
                    "if": {"properties": {v.on: {"const": case}}, "required": [v.on]},
                    "then": {
                        "properties": {n: False for n in keys if n not in allowed},
                        "required": [
                            n
                            for n in keys
                            if n in allowed and keys[n][1].required and not keys[n][1].when
                        ],
                    },
                }
            )
        if v.instead:
            other, _, beside = v.instead
            variable |= {v.on} | set(v.common)
            rules.append(
                {
                    "if": {"required": [other]},
                    "then": {"properties": {n: False for n in keys if n not in (other, *beside)}},
                }
            )
            rules.append(
                {
                    "if": {"minProperties": 1},
                    "then": {"anyOf": [{"required": [v.on]}, {"required": [other]}]},
                }
            )
    for name, (_, k) in keys.items():
        for sibling, allowed in k.when.items():
            sf, sk = keys[names[sibling]]
            values = sk.type.json_values(allowed) if isinstance(sk.type, Choice) else allowed
            sib = names[sibling]
            if sf.default is None or sf.default in allowed:
                unmet = {"properties": {sib: {"not": {"enum": values}}}, "required": [sib]}
            else:
                unmet = {"not": {"properties": {sib: {"enum": values}}, "required": [sib]}}
            rules.append({"if": unmet, "then": {"properties": {name: False}}})
            if k.required:
                met = {"properties": {sib: {"enum": values}}, "required": [sib]}
                rules.append({"if": met, "then": {"required": [name]}})
    for check in spec.rules:
        rules.extend(getattr(check, "json", []))
    required = [n for n, (f, k) in keys.items() if k.required and not k.when and n not in variable]
    if required:
        out["required"] = required
    if spec.one_of:
        out |= {"minProperties": 1, "maxProperties": 1}
    if rules:
        out["allOf"] = rules
    return out


# --- the reference page ------------------------------------------------------------


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _shown(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    if isinstance(value, (str, Path)):
        return f"'{value}'"
    return str(value)


def _default_text(name: str, f: dataclasses.Field, k: Key, spec) -> str:
    if k.default_doc is not None:
        return k.default_doc
    if k.required and (v := spec.variants) and name not in (v.on, *v.common):
        owners = [case for case, names in v.cases.items() if name in names]
        if len(owners) < len(v.cases):
            return f"required for {v.name(owners)}"
    if k.required:
        return "required"
    if f.default is dataclasses.MISSING:
        return "(the table's defaults)"
    return "none" if f.default is None else _shown(f.default)


def tables(cls=Scene, path: str = "", heading: str = ""):
    """(key path, heading, table class) of ``cls`` and of every table below it."""
    yield path, heading, cls
    for name, (_, k) in keys_of(cls).items():
        sub = _join(path, name)
        if isinstance(k.type, Sub):
            yield from tables(k.type.cls, sub, f"[{sub}]")
        elif isinstance(k.type, Each):
            yield from tables(k.type.cls, sub, f"[[{sub}]]")


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _section(path: str, heading: str, cls) -> list[str]:
    spec = cls.__table__
    keys = keys_of(cls)
    lines = [f"## `{heading}`" if path else "## The top level", "", spec.doc, ""]
    lines += ["| key | type | unit | allowed | default | meaning |", "|---|---|---|---|---|---|"]
    for name, (f, k) in keys.items():
        if isinstance(k.type, (Sub, Each)):
            kind = "table" if isinstance(k.type, Sub) else "array of tables"
            allowed = f"see `{'[' if isinstance(k.type, Sub) else '[['}{_join(path, name)}"
            allowed += "]`" if isinstance(k.type, Sub) else "]]`"
        else:
            kind, allowed = k.type.type_text, k.type.allowed_text()
        doc = k.doc
        if k.when:
            conditions = " and ".join(
                f"{s} = " + " or ".join(repr(a) for a in allowed_) for s, allowed_ in k.when.items()
            )
            doc += f"; only with {conditions}"
        row = [f"`{name}`", kind, k.unit, allowed, _default_text(name, f, k, spec), doc]
        lines.append("| " + " | ".join(_cell(c) for c in row) + " |")
    lines.append("")
    if v := spec.variants:
        if set(map(tuple, v.cases.values())) != {tuple(next(iter(v.cases.values())))}:
            lines.append(f"Keys by `{v.on}` (besides `{v.on}`, {', '.join(v.common)}):")
            lines.append("")
            for case, own in v.cases.items():
                lines.append(f"- `{case}`: {', '.join(own)}")
            if v.instead:
                other, noun, beside = v.instead
                lines.append(f"- `{other}` instead of `{v.on}` ({noun}): only {', '.join(beside)}")
            lines.append("")
    if spec.one_of:
        lines += [f"Give exactly one of {', '.join(keys)}.", ""]
    if spec.rules:
        lines += ["Rules:", ""]
        lines += ["- " + " ".join(check.__doc__.split()) for check in spec.rules]
        lines.append("")
    return lines


def reference_page() -> str:
    """``docs/reference/scene.md``: every table and key of the scene format."""
    lines = [
        "# Scene reference",
        "",
        "<!-- Written by `python -m rwall_fem.scene.reference` from rwall_fem/scene/schema.py;"
        " do not edit. -->",
        "",
        "A scene is a TOML file (UTF-8) in SI units: m, s, kg, Pa. `rwall-fem check scene.toml`"
        " checks it whole and refuses a mistake in one line: the file, the key path and what is"
        " allowed. `--set key.path=value` (e.g. `--set wall[0].slide=tied`) changes a key"
        " before the check. `demos/every_key.toml` uses every key.",
        "",
        "The JSON Schema `rwall_fem/scene/scene.schema.json` (installed with the package) lets"
        " a TOML editor complete and check scenes, e.g. with a first line"
        " `#:schema path/to/scene.schema.json` (taplo, Even Better TOML). It knows the types,"
        " ranges, choices and which keys go together; the rules below that compare numbers"
        " across keys are checked by `rwall-fem check` only.",
        "",
        "A table's key with a table as its value may also be written inline:"
        " `noise = {amplitude = 1e-7, seed = 7}`.",
        "",
    ]
    for path, heading, cls in tables():
        lines += _section(path, heading, cls)
    return "\n".join(lines).rstrip() + "\n"


def write(root: Path | None = None) -> None:
    """Write the reference page and the JSON Schema into the repository at ``root`` (by
    default the one this package is in)."""
    page = (root or Path(__file__).resolve().parents[2]) / PAGE
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(reference_page())
    SCHEMA_FILE.write_text(json.dumps(json_schema(), indent=2) + "\n")


if __name__ == "__main__":
    write()
