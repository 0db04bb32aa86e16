"""The vocabulary of the scene schema: keys, value types, tables and the reader.

A table of a scene is a frozen dataclass whose fields carry a :class:`Key` in
their metadata (``key(...)``): the value type, unit, default and a one-line
doc; the field name is the TOML name unless the key says otherwise.
:func:`read_table` checks a raw TOML table against those declarations and
builds the dataclass; :mod:`rwall_fem.scene.reference` writes the reference
page and the JSON Schema from the same declarations.

Every refusal is a :class:`SceneError` of one line,
``<file>: <key.path>: <what is wrong and what is allowed>``.
"""

from __future__ import annotations

import dataclasses
import datetime
import difflib
import functools
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

__all__ = [
    "Choice",
    "Context",
    "Curve",
    "Each",
    "Flag",
    "Identifier",
    "Integer",
    "Invalid",
    "Key",
    "Letters",
    "MeshFile",
    "Names",
    "Real",
    "SceneError",
    "Sub",
    "TableSpec",
    "Text",
    "Variants",
    "Vector",
    "did_you_mean",
    "Velocity",
    "key",
    "keys_of",
    "join",
    "read_table",
    "rule",
    "show",
    "table",
]

INT64_MAX = 2**63 - 1  # integers go to NumPy and gmsh


class SceneError(ValueError):
    """A scene that cannot run; the message is one line meant for the user."""


class Invalid(Exception):
    """A value that does not fit its type; the message follows ``<key.path>: ``."""


# --- showing values and key paths in one line -----------------------------------


def show(value: Any, depth: int = 0) -> str:
    """``value`` as a short TOML-like text on one line, whatever it is."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        if abs(value) < 10**20:
            return str(value)
        try:
            return f"a {len(str(abs(value)))}-digit integer"
        except ValueError:  # beyond Python's digit limit for str()
            return "an integer of thousands of digits"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        text = value if len(value) <= 40 else value[:37] + "..."
        return repr(text)
    if isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        return f"the date/time {value.isoformat()}"
    if isinstance(value, (list, tuple)):
        if depth >= 2:
            return "[...]" if value else "[]"
        items = [show(v, depth + 1) for v in value[:4]]
        return "[" + ", ".join(items + (["..."] if len(value) > 4 else [])) + "]"
    if isinstance(value, dict):
        if depth >= 2:
            return "{...}" if value else "{}"
        items = [f"{_name(str(k))} = {show(v, depth + 1)}" for k, v in list(value.items())[:3]]
        return "{" + ", ".join(items + (["..."] if len(value) > 3 else [])) + "}"
    return f"a {type(value).__name__}"


def _name(name: str) -> str:
    """A key as TOML writes it: bare when it can be, quoted (one line) otherwise."""
    if re.fullmatch(r"[A-Za-z0-9_-]+", name):
        return name
    return '"' + name.encode("unicode_escape").decode("ascii").replace('"', '\\"') + '"'


def join(path: str, name: str) -> str:
    """The key path of ``name`` inside the table at ``path``."""
    return f"{path}.{_name(name)}" if path else _name(name)


def _or(words) -> str:
    words = list(words)
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


# --- value types ----------------------------------------------------------------


@dataclass(frozen=True)
class Context:
    """Where a value is read: the scene's file, the folder relative paths start from, the
    key path, and the values of the keys of the same table read so far (by field name)."""

    source: str
    base: Path
    path: str = ""
    values: dict = field(default_factory=dict)

    def at(self, path: str, values: dict | None = None) -> Context:
        return Context(self.source, self.base, path, self.values if values is None else values)

    def fail(self, path: str, message: str) -> NoReturn:
        where = f"{path}: " if path else ""
        raise SceneError(f"{self.source}: {where}{message}")


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _float(value) -> float:
    try:
        return float(value)
    except OverflowError:  # an integer of hundreds of digits
        return math.inf if value > 0 else -math.inf


class ValueType:
    """How one TOML value is checked (:meth:`read`) and described (docs, JSON Schema)."""

    type_text = "value"  # for the reference page

    def read(self, value: Any, ctx: Context) -> Any:
        raise NotImplementedError

    def allowed_text(self) -> str:
        return ""

    def json(self) -> dict:
        return {}


@dataclass(frozen=True)
class Real(ValueType):
    """A finite number (an integer is taken as a float) within bounds; a bound may be the
    name of a key of the same table read before this one (``high="element_size"``)."""

    low: float | str | None = None
    high: float | str | None = None
    low_open: bool = True
    high_open: bool = False
    type_text = "number"

    def read(self, value, ctx):
        if not _is_number(value):
            raise Invalid(f"must be a number, got {show(value)}")
        x = _float(value)
        low, high = (ctx.values[b] if isinstance(b, str) else b for b in (self.low, self.high))
        ok = math.isfinite(x)
        if low is not None:
            ok = ok and (x > low if self.low_open else x >= low)
        if high is not None:
            ok = ok and (x < high if self.high_open else x <= high)
        if not ok:
            raise Invalid(f"must be a finite number {self._span(low, high)}, got {show(value)}")
        return x

    def _span(self, low, high) -> str:
        def text(b):
            return b if isinstance(b, str) else f"{b:g}"

        lo = "(-inf" if low is None else ("(" if self.low_open else "[") + text(low)
        hi = "inf)" if high is None else text(high) + (")" if self.high_open else "]")
        return f"in {lo}, {hi}"

    def allowed_text(self):
        if self.low is None and self.high is None:
            return "finite"
        return self._span(self.low, self.high).removeprefix("in ")

    def json(self):
        out: dict = {"type": "number"}
        if isinstance(self.low, (int, float)):
            out["exclusiveMinimum" if self.low_open else "minimum"] = self.low
        if isinstance(self.high, (int, float)):
            out["exclusiveMaximum" if self.high_open else "maximum"] = self.high
        return out


@dataclass(frozen=True)
class Integer(ValueType):
    """An integer (not a float, not a boolean) in [low, high]; ``why``: where high comes from."""

    low: int = 0
    high: int | None = None
    why: str = ""
    type_text = "integer"

    def read(self, value, ctx):
        high = INT64_MAX if self.high is None else self.high
        if isinstance(value, int) and not isinstance(value, bool) and self.low <= value <= high:
            return value
        span = f">= {self.low}" if self.high is None else f"in {self.allowed_text()}"
        raise Invalid(f"must be an integer {span}, got {show(value)}")

    def allowed_text(self):
        if self.high is None:
            return f">= {self.low}"
        return f"[{self.low}, {self.high}]" + (f" ({self.why})" if self.why else "")

    def json(self):
        return {"type": "integer", "minimum": self.low, "maximum": self.high or INT64_MAX}


@dataclass(frozen=True)
class Flag(ValueType):
    """``true`` or ``false``: 1 and "yes" are refused."""

    type_text = "boolean"

    def read(self, value, ctx):
        if not isinstance(value, bool):
            raise Invalid(f"must be true or false, got {show(value)}")
        return value

    def allowed_text(self):
        return "true, false"

    def json(self):
        return {"type": "boolean"}


@dataclass(frozen=True)
class Choice(ValueType):
    """One of ``options`` (strings), or an integer ``aliases`` maps to one of them."""

    options: tuple[str, ...]
    aliases: dict = field(default_factory=dict)

    @property
    def type_text(self):
        return "string or integer" if self.aliases else "string"

    def read(self, value, ctx):
        if isinstance(value, str) and value in self.options:
            return value
        if type(value) is int and value in self.aliases:
            return self.aliases[value]
        raise Invalid(f"must be one of {self.allowed_text()}, got {show(value)}")

    def allowed_text(self):
        text = ", ".join(map(repr, self.options))
        if self.aliases:
            text += " (or the integers " + ", ".join(map(str, self.aliases)) + ")"
        return text

    def json(self):
        return {"enum": [*self.options, *self.aliases]}

    def json_values(self, values) -> list:
        """The TOML values that read as one of ``values``: the option and its aliases."""
        return [*values, *(a for a, v in self.aliases.items() if v in values)]


@dataclass(frozen=True)
class Text(ValueType):
    """A non-empty string: ``what`` it names; ``path=True`` gives a :class:`~pathlib.Path`."""

    what: str
    path: bool = False
    type_text = "string"

    def read(self, value, ctx):
        if not isinstance(value, str) or not value:
            raise Invalid(f"must be {self.what}, got {show(value)}")
        return Path(value) if self.path else value

    def json(self):
        return {"type": "string", "minLength": 1}


@dataclass(frozen=True)
class Identifier(ValueType):
    """A name that heads columns of the outputs (``what`` it names): a letter, then up to 63
    letters, digits, ``_`` or ``-``."""

    what: str
    type_text = "string"
    PATTERN = r"[A-Za-z][A-Za-z0-9_-]{0,63}"

    def read(self, value, ctx):
        if not isinstance(value, str) or not re.fullmatch(self.PATTERN, value):
            raise Invalid(
                f"must be {self.what}: a letter, then up to 63 letters, digits, '_' or '-'; "
                f"got {show(value)}"
            )
        return value

    def allowed_text(self):
        return "a letter, then up to 63 letters, digits, `_`, `-`"

    def json(self):
        return {"type": "string", "pattern": f"^{self.PATTERN}$"}


@dataclass(frozen=True)
class MeshFile(ValueType):
    """A gmsh ``.msh`` or ``.geo`` file, relative to the scene file's folder."""

    type_text = "string"

    def read(self, value, ctx):
        if not isinstance(value, str) or not value:
            raise Invalid(f"must be a path string, got {show(value)}")
        try:
            file = (ctx.base / value).resolve()
            found = file.is_file()
        except (OSError, RuntimeError):  # a loop of links (RuntimeError up to Python 3.12)
            raise Invalid(f"{show(value)} is a loop of symbolic links, not a mesh file") from None
        except ValueError:  # e.g. a NUL character
            found = False
            file = Path(value)
        if not found and file.exists():
            raise Invalid(f"{show(str(file))} is not a file (a folder, a device or a pipe)")
        if not found:
            raise Invalid(f"mesh file not found: {show(str(file))}")
        if file.suffix not in (".msh", ".geo"):
            raise Invalid(f"must be a gmsh .msh or .geo file, got {show(file.name)}")
        return file

    def allowed_text(self):
        return "an existing .msh or .geo file, relative to the scene file"

    def json(self):
        return {"type": "string", "pattern": r"\.(msh|geo)$"}


def _numbers(value, size: int) -> bool:
    return (
        isinstance(value, (list, tuple))
        and len(value) == size
        and all(_is_number(c) and math.isfinite(_float(c)) for c in value)
    )


@dataclass(frozen=True)
class Vector(ValueType):
    """``size`` finite numbers [x, y(, z)]; ``kind`` "positive" (lengths) or "direction"
    (not all zero) narrows them."""

    size: int = 3
    kind: str = "finite"

    @property
    def type_text(self):
        return "[" + ", ".join("xyz"[: self.size]) + "]"

    def read(self, value, ctx):
        names = ", ".join("xyz"[: self.size])
        if self.kind == "positive":
            if not _numbers(value, self.size) or min(value) <= 0:
                raise Invalid(f"must be {self.size} positive lengths [{names}], got {show(value)}")
        elif not _numbers(value, self.size):
            raise Invalid(f"must be {self.size} finite numbers [{names}], got {show(value)}")
        elif self.kind == "direction" and not any(value):
            raise Invalid(f"must be a non-zero direction [{names}], got {show(value)}")
        elif self.kind == "non_negative" and min(value) < 0:
            raise Invalid(f"must be {self.size} numbers >= 0 [{names}], got {show(value)}")
        return tuple(float(c) for c in value)

    def allowed_text(self):
        return {"finite": "finite", "positive": "each > 0", "direction": "not all 0",
                "non_negative": "each >= 0"}[self.kind]  # fmt: skip

    def json(self):
        item: dict = {"type": "number"}
        if self.kind == "positive":
            item["exclusiveMinimum"] = 0
        if self.kind == "non_negative":
            item["minimum"] = 0
        out = {"type": "array", "items": item, "minItems": self.size, "maxItems": self.size}
        if self.kind == "direction":
            out["not"] = {"items": {"const": 0}}
        return out


@dataclass(frozen=True)
class Velocity(ValueType):
    """A constant velocity [vx, vy, vz], or a history: rows [t, vx, vy, vz] with increasing t
    (piecewise linear in between, held outside them)."""

    type_text = "[x, y, z] or rows [t, vx, vy, vz]"

    def read(self, value, ctx):
        if isinstance(value, (list, tuple)) and value and isinstance(value[0], (list, tuple)):
            if not all(_numbers(r, 4) for r in value) or any(
                b[0] <= a[0] for a, b in zip(value, value[1:], strict=False)
            ):
                raise Invalid("a table must be rows [t, vx, vy, vz] with increasing t")
            return tuple(tuple(float(x) for x in r) for r in value)
        return Vector(3).read(value, ctx)

    def allowed_text(self):
        return "finite; rows with increasing t"

    def json(self):
        row = {"type": "array", "items": {"type": "number"}, "minItems": 4, "maxItems": 4}
        return {"anyOf": [Vector(3).json(), {"type": "array", "items": row, "minItems": 1}]}


@dataclass(frozen=True)
class Curve(ValueType):
    """A tabulated curve: rows [x, y] with x starting at ``first_x`` and increasing, y > 0,
    at most ``rows`` rows (linear between rows, held beyond the last)."""

    first_x: float = 0.0
    rows: int = 64
    type_text = "rows [x, y]"

    def read(self, value, ctx):
        ok = (
            isinstance(value, (list, tuple))
            and 2 <= len(value) <= self.rows
            and all(_numbers(r, 2) and _float(r[1]) > 0 for r in value)
        )
        if ok:
            x = [_float(r[0]) for r in value]
            ok = x[0] == self.first_x and all(b > a for a, b in zip(x, x[1:], strict=False))
        if not ok:
            raise Invalid(
                f"must be 2 to {self.rows} rows [x, y], x from {self.first_x:g} increasing, "
                f"y > 0, got {show(value)}"
            )
        return tuple((_float(r[0]), _float(r[1])) for r in value)

    def allowed_text(self):
        return f"2 to {self.rows} rows; x from {self.first_x:g} increasing; y > 0"

    def json(self):
        row = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}
        return {"type": "array", "items": row, "minItems": 2, "maxItems": self.rows}


@dataclass(frozen=True)
class Factor(ValueType):
    """A history of a factor: rows [t, y] with increasing t, any finite y (linear between
    rows, held outside them)."""

    type_text = "rows [t, y]"

    def read(self, value, ctx):
        ok = isinstance(value, (list, tuple)) and len(value) >= 1
        ok = ok and all(_numbers(r, 2) for r in value)
        if ok:
            t = [_float(r[0]) for r in value]
            ok = all(b > a for a, b in zip(t, t[1:], strict=False))
        if not ok:
            raise Invalid(f"must be rows [t, y] with increasing t, got {show(value)}")
        return tuple((_float(r[0]), _float(r[1])) for r in value)

    def allowed_text(self):
        return "finite; rows with increasing t"

    def json(self):
        row = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}
        return {"type": "array", "items": row, "minItems": 1}


@dataclass(frozen=True)
class Names(ValueType):
    """A list of node-set names (gmsh physical groups)."""

    type_text = "array of strings"

    def read(self, value, ctx):
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise Invalid(f"must be a list of node-set names, got {show(value)}")
        return tuple(value)

    def json(self):
        return {"type": "array", "items": {"type": "string"}}


@dataclass(frozen=True)
class NodeSets(ValueType):
    """One node-set name, or a non-empty list of them (their union: a node is in it once)."""

    type_text = "string or array of strings"

    def read(self, value, ctx):
        if isinstance(value, str) and value:
            return (value,)
        if (
            isinstance(value, (list, tuple))
            and value
            and all(isinstance(v, str) and v for v in value)
        ):
            return tuple(dict.fromkeys(value))
        raise Invalid(f"must be a node-set name or a list of them, got {show(value)}")

    def allowed_text(self):
        return "names of face groups of the mesh"

    def json(self):
        name = {"type": "string", "minLength": 1}
        return {"anyOf": [name, {"type": "array", "items": name, "minItems": 1}]}


@dataclass(frozen=True)
class Letters(ValueType):
    """Some of the letters x, y, z, each at most once (returned sorted)."""

    type_text = "string"

    def read(self, value, ctx):
        if (
            not isinstance(value, str)
            or not value
            or any(c not in "xyz" for c in value)
            or len(set(value)) != len(value)
        ):
            raise Invalid(f"must be some of the letters x, y, z once, got {show(value)}")
        return "".join(sorted(value))

    def allowed_text(self):
        return "some of x, y, z once"

    def json(self):
        return {"type": "string", "pattern": r"^(?!.*(.).*\1)[xyz]{1,3}$"}


@dataclass(frozen=True)
class Sub(ValueType):
    """A table read as the dataclass ``cls``; ``then`` turns it into the field's value;
    ``empty_is_none``: an empty table means "not given"."""

    cls: type
    then: Callable | None = None
    empty_is_none: bool = False
    type_text = "table"

    def read(self, value, ctx):
        if isinstance(value, dict) and not value and self.empty_is_none:
            return None
        out = read_table(self.cls, value, ctx)
        return self.then(out) if self.then else out


@dataclass(frozen=True)
class Each(ValueType):
    """An array of tables ``[[name]]``, each read as the dataclass ``cls``; a tuple."""

    cls: type
    type_text = "array of tables"

    def read(self, value, ctx):
        if not isinstance(value, (list, tuple)):
            name = ctx.path.rpartition(".")[2]
            raise Invalid(f"must be an array of tables: write [[{name}]]")
        return tuple(
            read_table(self.cls, v, ctx.at(f"{ctx.path}[{i}]")) for i, v in enumerate(value)
        )


# --- keys and tables ------------------------------------------------------------


@dataclass(frozen=True)
class Key:
    """One key of a table: its value type, unit, one-line doc and conditions.

    ``required``: no default in the scene (a variant's key is required in its variants);
    ``when``: {sibling field: values} under which the key exists at all (it is refused
    otherwise; a sibling still None is decided elsewhere); ``default_doc``: the default as
    the reference page writes it, when the field's value does not say it.
    """

    type: ValueType
    unit: str = ""
    doc: str = ""
    required: bool = False
    when: dict = field(default_factory=dict)
    default_doc: str | None = None
    toml: str | None = None


def key(
    type: ValueType,
    default: Any = dataclasses.MISSING,
    *,
    doc: str,
    unit: str = "",
    required: bool | None = None,
    when: dict | None = None,
    default_doc: str | None = None,
    toml: str | None = None,
    factory: Callable | None = None,
) -> Any:
    """A dataclass field that is a key of the scene (see :class:`Key`)."""
    k = Key(
        type,
        unit,
        doc,
        (default is dataclasses.MISSING and factory is None) if required is None else required,
        when or {},
        default_doc,
        toml,
    )
    if factory is not None:
        return field(default_factory=factory, metadata={"key": k})
    return field(default=default, metadata={"key": k})


@dataclass(frozen=True)
class Variants:
    """Keys that depend on the value of the key ``on`` (a wall's kind, a mesh's shape).

    ``cases``: value -> its own keys; ``common``: keys of every case; ``noun``: how a case
    is named in messages ("a {} wall"); ``instead``: (key, noun, its keys) of a key that
    stands instead of ``on`` (a mesh file instead of a shape), with only ``its keys`` beside.
    """

    on: str
    cases: dict
    common: tuple = ()
    noun: str = "a {}"
    instead: tuple | None = None

    def name(self, cases) -> str:
        return self.noun.format(_or(cases))


@dataclass
class TableSpec:
    """What a table of the scene is besides its keys: doc, variants, cross-key rules."""

    doc: str
    variants: Variants | None = None
    one_of: bool = False  # exactly one of its keys
    rules: list = field(default_factory=list)


def table(doc: str, *, variants: Variants | None = None, one_of: bool = False):
    """Class decorator: the dataclass is a table of the scene."""

    def mark(cls):
        cls.__table__ = TableSpec(doc, variants, one_of)
        return cls

    return mark


def rule(cls, json: list[dict] = ()):
    """Decorator: ``fn(values, raw, fail)`` checks the keys of ``cls``'s table together (its
    docstring is the rule's line on the reference page). ``values`` maps field names to the
    values read (defaults filled in) and may be completed; ``fail(key, message)`` refuses.
    ``json``: what the JSON Schema can say of the rule (subschemas of the table's allOf)."""

    def register(fn):
        fn.json = list(json)
        cls.__table__.rules.append(fn)
        return fn

    return register


@functools.cache
def keys_of(cls) -> dict[str, tuple[dataclasses.Field, Key]]:
    """TOML name -> (dataclass field, key) of the table ``cls``, in declaration order."""
    return {
        f.metadata["key"].toml or f.name: (f, f.metadata["key"])
        for f in dataclasses.fields(cls)
        if "key" in f.metadata
    }


def _default(f: dataclasses.Field) -> Any:
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return f.default


def did_you_mean(name: str, allowed) -> str:
    """' (did you mean 'x'?)' with the closest of ``allowed`` to ``name``, or nothing."""
    close = (
        difflib.get_close_matches(name, allowed, n=1)
        or [a for a in allowed if name and (a.startswith(name) or name.startswith(a))][:1]
    )
    return f" (did you mean '{close[0]}'?)" if close else ""


def _unmet(k: Key, values: dict) -> str | None:
    """The first condition of ``k.when`` that the values read do not meet, as a message."""
    for sibling, allowed in k.when.items():
        value = values[sibling]
        if value is not None and value not in allowed:
            need = _or([repr(a) for a in allowed])
            return f"needs {sibling} = {need} ({sibling} is {value!r})"
    return None


def read_table(cls, raw: Any, ctx: Context, extra: dict | None = None) -> Any:
    """Check the raw TOML table ``raw`` at ``ctx.path`` against ``cls`` and build it."""
    spec: TableSpec = cls.__table__
    path = ctx.path
    if not isinstance(raw, dict):
        ctx.fail(path, f"must be a table, got {show(raw)}")
    keys = keys_of(cls)
    for name in raw:
        if name not in keys:
            name = str(name)  # a dict from Python may have other keys than strings
            ctx.fail(
                join(path, name),
                f"unknown key{did_you_mean(name, keys)}; allowed: {', '.join(keys)}",
            )
    if spec.one_of and len(raw) != 1:
        ctx.fail(path, f"give exactly one of {', '.join(keys)}")

    values: dict = dict(extra or {})

    def read(name):
        f, k = keys[name]
        try:
            return k.type.read(raw[name], ctx.at(join(path, name), values))
        except Invalid as err:
            ctx.fail(join(path, name), str(err))

    present = set(keys)
    if v := spec.variants:
        if v.instead and v.instead[0] in raw:
            other, noun, beside = v.instead
            if v.on in raw:
                ctx.fail(path, f"give either '{v.on}' or '{other}', not both")
            present = {other, *beside}
        else:
            if v.on not in raw:
                alternative = f" (or give '{v.instead[0]}')" if v.instead else ""
                ctx.fail(join(path, v.on), f"missing{alternative}")
            case = read(v.on)
            present = {v.on, *v.cases[case], *v.common}
            noun = v.name([case])
        for name in raw:
            if name not in present:
                owners = [c for c, names in v.cases.items() if name in names]
                belongs = f" (it belongs to {v.name(owners)})" if owners else ""
                allowed = ", ".join(n for n in keys if n in present and n != v.on)
                ctx.fail(join(path, name), f"is not a key of {noun}{belongs}; allowed: {allowed}")

    # Declaration order: a key's conditions and bounds refer to keys declared before it.
    for name, (f, k) in keys.items():
        if name not in present:  # a key of another variant, not given
            values[f.name] = _default(f)
        elif unmet := _unmet(k, values):
            if name in raw:
                ctx.fail(join(path, name), unmet)
            values[f.name] = _default(f)
        elif name in raw:
            values[f.name] = read(name)
        elif k.required:
            ctx.fail(join(path, name), "missing")
        else:
            values[f.name] = _default(f)

    def fail(name: str, message: str) -> NoReturn:  # ``name``: a key path below this table
        ctx.fail(f"{path}.{name}" if path and name else name or path, message)

    for check in spec.rules:
        check(values, raw, fail)
    return cls(**values)
