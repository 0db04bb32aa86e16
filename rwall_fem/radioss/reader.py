"""The Radioss block format's cards and data lines, and the numbers in their fields.

A card starts with a line beginning ``/`` (``/RWALL/PLANE/1``) and holds the data lines
up to the next one (the files of a deck are cut into cards by
:mod:`~rwall_fem.radioss.deck_files`). A data line is fixed format (fields of 10 or 20
characters, a blank field meaning the default) unless it holds a comma or a tab: then
its fields are the words of the line in order (the free format; commas separate, or
else blanks and tabs). Every line remembers its file and number, so that every refusal
names them: :class:`DeckError`, one line, ``file:line: /CARD: what; allowed``.

Numbers are read as Radioss reads them: a Fortran ``D`` exponent (``2.1D5``) or none
(``2.1+5``, ``7.8-9``) is an exponent, an integer field may hold an integral real
(``1.``, ``1.0D0``). A number that is not finite (``nan``, ``inf``, ``1e999``) or an
integer of more than 10 digits (Radioss's IDs and flags) is refused naming the field.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from rwall_fem.scene import SceneError

__all__ = [
    "MAX_DIGITS",
    "Card",
    "DeckError",
    "Line",
    "fixed_table",
    "parse_number",
    "read_fields",
]

MAX_DIGITS = 10  # Radioss's integers (IDs, flags): "Integer, maximum 10 digits"

# A real whose exponent has no letter, as Fortran writes it in narrow fields: 2.1+5.
_BARE_EXPONENT = re.compile(r"([+-]?(?:\d+\.?\d*|\.\d+))([+-]\d+)")


class DeckError(SceneError):
    """A deck that cannot become a scene; the message is one line naming file and line.

    A :class:`~rwall_fem.scene.SceneError`, so the command line reports it as any bad
    scene: one line on stderr, exit code 2."""


class NumberError(ValueError):
    """A field that is not a number of its kind; the message says why (after the field)."""


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
        """Whether the line is in the free format (comma- or tab-separated fields)."""
        return "," in self.text or "\t" in self.text

    def words(self) -> list[str]:
        """The fields of a line with commas, or else its words (blanks and tabs)."""
        if "," in self.text:
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

    def read_optional(self, index: int, layout: str) -> list:
        """The fields of data line ``index``, or the defaults (0, 0.0, '') of the layout if
        the card has no such line (Radioss's optional lines)."""
        if index < len(self.lines):
            return read_fields(self, self.lines[index], layout)
        return [{"i": 0, "f": 0.0, "s": ""}[k] for k, _, _ in _columns(layout) if k != "-"]


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
        except NumberError as err:
            card.fail(f"field {name} ({at}): {err}", line)
    return values


def parse_number(text: str, integer: bool = False):
    """A Radioss number: blank is 0; ``D`` or no letter before the exponent; an integral
    real in an integer field. :class:`NumberError` (a ValueError) says why one is not."""
    text = text.strip()
    if not text:
        return 0 if integer else 0.0
    digits = text.lstrip("+-")
    if integer and digits.isascii() and digits.isdigit() and len(text) - len(digits) <= 1:
        if len(digits.lstrip("0")) > MAX_DIGITS:
            raise NumberError(
                f"{_shown(text)} has {len(digits.lstrip('0'))} digits; Radioss's integers "
                f"(IDs, flags) have at most {MAX_DIGITS}"
            )
        value = int(text)
    else:
        value = _real(text, integer)
        if integer:
            if not value.is_integer():
                raise NumberError(f"{text!r} is not an integer")
            value = int(value)
    if integer and abs(value) >= 10**MAX_DIGITS:
        digits = len(str(abs(value)))
        raise NumberError(
            f"{_shown(text)} has {digits} digits; Radioss's integers (IDs, flags) have at most "
            f"{MAX_DIGITS}"
        )
    return value


def _real(text: str, integer: bool) -> float:
    spelled = text.replace("D", "E").replace("d", "e")
    bare = _BARE_EXPONENT.fullmatch(spelled)
    if bare:
        spelled = f"{bare[1]}E{bare[2]}"
    try:
        value = float(spelled)
    except ValueError:
        need = "an integer" if integer else "a number"
        raise NumberError(f"cannot read {_shown(text)} as {need}{_odd_character(text)}") from None
    if not math.isfinite(value):
        raise NumberError(f"{_shown(text)} is not a finite number")
    return value


def _shown(text: str) -> str:
    return repr(text) if len(text) <= 24 else repr(text[:21] + "...")


def _odd_character(text: str) -> str:
    """What is odd in a field that does not read: its first character beyond ASCII."""
    for k, c in enumerate(text):
        if not c.isascii():
            return f" (the character {c!r}, U+{ord(c):04X}, at its character {k + 1})"
    return ""


def fixed_table(card: Card, start: int, layout: str) -> list[np.ndarray]:
    """The fields of the data lines ``start:`` of ``card`` as arrays, one per field of
    ``layout`` (integers as int64, reals as float64): NumPy on the fixed columns, so a
    million lines read in seconds; free-format lines, and columns NumPy does not read
    (a bare exponent, a number that is not finite), are read line by line, so that a
    field that does not parse is refused naming its line."""
    lines = card.lines[start:]
    columns = _columns(layout)
    kinds = [k for k, _, _ in columns if k != "-"]
    types = [np.int64 if k == "i" else float for k in kinds]
    if not lines:
        return [np.zeros(0, dtype=t) for t in types]
    if not any(line.free for line in lines):
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
            except (ValueError, OverflowError):
                pass
            else:
                if all(np.isfinite(a).all() for a in out if a.dtype == float):
                    return out
    rows = [read_fields(card, line, layout) for line in lines]
    return [np.array([r[i] for r in rows], dtype=t) for i, t in enumerate(types)]


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
