"""The Radioss block format, read into cards: no meaning yet, only lines and fields.

A deck is a starter file (``NAME_0000.rad``) and an engine file (``NAME_0001.rad``). A
card starts with a line beginning ``/`` (``/RWALL/PLANE/1``) and holds the lines up to
the next one. Lines starting with ``#`` or ``$`` are comments, but ``#include FILE``,
which reads FILE (relative to the including file) in place. ``/END`` ends a file.

A data line is fixed format (fields of 10 or 20 characters, a blank field meaning the
default) unless it holds a comma: then its fields are the comma-separated words, in
order (the free format). Every line remembers its file and number, so that every
refusal names them: :class:`DeckError`, one line, ``file:line: /CARD: what; allowed``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rwall_fem.scene import SceneError

__all__ = ["Card", "DeckError", "Line", "read_cards"]


class DeckError(SceneError):
    """A deck that cannot become a scene; the message is one line naming file and line.

    A :class:`~rwall_fem.scene.SceneError`, so the command line reports it as any bad
    scene: one line on stderr, exit code 2."""


@dataclass(frozen=True)
class Line:
    """One data line of a card: its text and where it is (file, 1-based line number)."""

    text: str
    file: str
    number: int

    @property
    def where(self) -> str:
        return f"{self.file}:{self.number}"

    @property
    def free(self) -> bool:
        """Whether the line is in the free format (comma-separated fields)."""
        return "," in self.text

    def words(self) -> list[str]:
        """The fields of a free-format line, or the blank-separated words of the line."""
        if self.free:
            return [w.strip() for w in self.text.split(",")]
        return self.text.split()


@dataclass
class Card:
    """A card: its keyword parts (``["RWALL", "PLANE", "1"]``), where its header is, and
    its data lines (comments removed)."""

    parts: list[str]
    header: Line
    lines: list[Line] = field(default_factory=list)

    @property
    def name(self) -> str:
        return "/" + "/".join(self.parts)

    def key(self, index: int) -> str:
        """Keyword part ``index`` in capitals, '' past the end."""
        return self.parts[index].upper() if index < len(self.parts) else ""

    def fail(self, message: str, line: Line | None = None):
        where = (line or self.header).where
        raise DeckError(f"{where}: {self.name}: {message}")

    def line(self, index: int, what: str) -> Line:
        """Data line ``index`` (0-based), or a refusal naming the line that is missing."""
        if index < len(self.lines):
            return self.lines[index]
        last = self.lines[-1] if self.lines else self.header
        raise DeckError(
            f"{last.where}: {self.name}: truncated card: the line '{what}' is missing after "
            "this line"
        )

    def title(self) -> str:
        return self.lines[0].text.strip() if self.lines else ""

    def read(self, index: int, layout: str, what: str | None = None) -> list:
        """The fields of data line ``index`` by ``layout`` (see :func:`read_fields`)."""
        return read_fields(self, self.line(index, what or layout), layout)


def _columns(layout: str) -> list[tuple[str, str, int]]:
    """``"i:node_ID f:Mass 20"``-style layout -> (kind, name, width) per field.

    Each word is ``kind:name`` or ``kind:name:width``; kinds: i integer, f real, s text,
    ``-`` a blank field; widths default to 10 (i, s, -) and 20 (f)."""
    out = []
    for word in layout.split():
        kind, name, *width = word.split(":")
        out.append((kind, name, int(width[0]) if width else (20 if kind == "f" else 10)))
    return out


def read_fields(card: Card, line: Line, layout: str) -> list:
    """The values of ``line`` for the fields of ``layout``: fixed columns, or the words of
    a free-format line in order; a blank field is 0, 0.0 or ''."""
    columns = _columns(layout)
    if line.free:
        words = line.words()
        fields = [words[i] if i < len(words) else "" for i in range(len(columns))]
        where = [f"field {i + 1}" for i in range(len(columns))]
    else:
        fields, where, start = [], [], 0
        for _, _, width in columns:
            fields.append(line.text[start : start + width])
            where.append(f"columns {start + 1}-{start + width}")
            start += width
    values = []
    for (kind, name, _), text, at in zip(columns, fields, where, strict=True):
        if kind == "-":
            continue
        text = text.strip()
        if kind == "s":
            values.append(text)
            continue
        try:
            values.append(parse_number(text, integer=kind == "i"))
        except ValueError:
            need = "an integer" if kind == "i" else "a number"
            card.fail(f"field {name} ({at}): cannot read {text!r} as {need}", line)
    return values


def parse_number(text: str, integer: bool = False):
    """A Radioss number: blank is 0; a Fortran ``D`` exponent is read as ``E``."""
    text = text.strip()
    if not text:
        return 0 if integer else 0.0
    if integer:
        return int(text)
    return float(text.replace("D", "E").replace("d", "e"))


def read_cards(path: Path) -> list[Card]:
    """The cards of the file ``path`` and of the files it includes, in order."""
    cards: list[Card] = []
    _read_file(Path(path), cards, [])
    return cards


def _read_file(path: Path, cards: list[Card], stack: list[Path]) -> None:
    name = str(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        where = f"{stack[-1]}: " if stack else ""
        raise DeckError(f"{where}{name}: cannot read the deck file: {err.strerror}") from None
    if b"\0" in data:
        at = data.index(b"\0")
        raise DeckError(f"{name}: not a text file (binary data at byte {at})")
    text = data.decode("utf-8", errors="replace")
    current: Card | None = None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.rstrip("\r\n")
        head = line.lstrip()
        if head.lower().startswith("#include"):
            target = head[len("#include") :].strip().strip("'\"")
            included = (path.parent / target).resolve()
            if not target:
                raise DeckError(f"{name}:{number}: #include: no file named")
            if included in stack or included == path.resolve():
                raise DeckError(f"{name}:{number}: #include {target}: includes itself")
            if not included.is_file():
                raise DeckError(f"{name}:{number}: #include {target}: file not found")
            _read_file(included, cards, [*stack, path.resolve()])
            current = cards[-1] if cards else None
            continue
        if head.startswith(("#", "$")):
            continue
        if line.startswith("/"):
            parts = [p.strip() for p in line.strip().strip("/").split("/")]
            if parts == ["END"] or parts == ["end"]:
                return
            current = Card(parts, Line(line, name, number))
            cards.append(current)
        elif current is None:
            if line.strip():
                raise DeckError(f"{name}:{number}: data before the first card: {line.strip()!r}")
        else:
            current.lines.append(Line(line, name, number))


def fixed_table(card: Card, start: int, layout: str) -> list[np.ndarray]:
    """The fields of the data lines ``start:`` of ``card`` as arrays, one per field of
    ``layout`` (integers as int64, reals as float64): NumPy on the fixed columns, so a
    million lines read in seconds; free-format lines are read one by one. A field that
    does not parse is refused naming its line."""
    lines = card.lines[start:]
    columns = _columns(layout)
    kinds = [k for k, _, _ in columns if k != "-"]
    types = [np.int64 if k == "i" else float for k in kinds]
    if not lines:
        return [np.zeros(0, dtype=t) for t in types]
    if any(line.free for line in lines):
        rows = [read_fields(card, line, layout) for line in lines]
        return [np.array([r[i] for r in rows], dtype=t) for i, t in enumerate(types)]
    width = sum(w for _, _, w in columns)
    text = "".join(line.text[:width].ljust(width) for line in lines)
    if text.isascii():
        chars = np.frombuffer(text.encode("ascii"), dtype="S1").reshape(len(lines), width)
        out, first = [], 0
        try:
            for kind, _, w in columns:
                if kind != "-":
                    out.append(_column(chars[:, first : first + w], kind))
                first += w
            return out
        except ValueError:
            pass
    for line in lines:  # something did not parse: name the first line that does not
        read_fields(card, line, layout)
    raise AssertionError("unreachable: every line parsed one by one")  # pragma: no cover


def _column(chars: np.ndarray, kind: str) -> np.ndarray:
    """The numbers in the character columns ``chars`` (lines x width); blank is 0."""
    strings = np.ascontiguousarray(chars).view(f"S{chars.shape[1]}").ravel()
    strings = np.char.strip(strings)
    strings[strings == b""] = b"0"
    if kind == "i":
        return strings.astype(np.int64)
    try:
        return strings.astype(float)
    except ValueError:  # a Fortran D exponent, perhaps
        return np.char.replace(np.char.replace(strings, b"D", b"E"), b"d", b"e").astype(float)
