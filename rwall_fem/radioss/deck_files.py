"""The files of a deck cut into cards, as Radioss reads them.

A deck is a starter file ``NAME_0000.rad`` (``/BEGIN`` ... ``/END``) and an engine file
``NAME_0001.rad``, or one file holding both (Radioss's single-file input: the engine's
cards, ``/END/ENGINE``, then the starter's; the engine's cards may also follow the
starter's ``/END``, up to ``/END/ENGINE``). :func:`read_deck_text` returns the starter's
cards and the engine's, and notices: one line for each thing read in a way the user
may want to know about.

- Lines starting with ``#`` or ``$`` are comments, but ``#include FILE``, which reads
  FILE (relative to the including file) in place, and ``#enddata``, after which the
  rest of its file is not read.
- ``/END`` ends the starter (what follows is not read, but a one-file deck's engine);
  in an included file it ends that file.
- The lines of an included file before its first card continue the card that includes
  it, as if pasted in place; a block of them that starts with text rather than numbers
  is a free-text header (a copyright notice), skipped with a notice, as are the text
  lines before the first card of the deck.
- A file is UTF-8 (a byte-order mark is dropped), else Latin-1, whose columns are
  Radioss's byte columns; UTF-16 with its byte-order mark is read too. CRLF and CR line
  ends are line ends; blank lines at the end of a card are dropped. A space that is not
  ASCII (a no-break space) is read as a space, with one notice naming where.
"""

from __future__ import annotations

import codecs
import re
from dataclasses import dataclass, field
from pathlib import Path

from rwall_fem.radioss.reader import Card, DeckError, Line, NumberError, parse_number

__all__ = ["DeckText", "read_cards", "read_deck_text"]

# Unicode spaces that editors and word processors put where a space was meant.
_ODD_SPACES = re.compile("[\u00a0\u1680\u2000-\u200a\u202f\u205f\u3000]")
_NAMES = {"\u00a0": "a no-break space", "\u202f": "a narrow no-break space",
          "\u3000": "an ideographic space"}  # fmt: skip


@dataclass
class DeckText:
    """The cards of a deck file: ``starter`` (``/BEGIN`` to ``/END``; empty in an engine
    file), ``engine`` (the others, up to ``/END`` or ``/END/ENGINE``), whether the file
    holds an engine block ``/END/ENGINE`` closes, and ``notices``."""

    starter: list[Card] = field(default_factory=list)
    engine: list[Card] = field(default_factory=list)
    engine_block: bool = False
    notices: list[str] = field(default_factory=list)


@dataclass
class _End:
    """``/END`` (``engine``: ``/END/ENGINE``) where it is."""

    engine: bool
    where: str


def read_cards(path: str | Path) -> list[Card]:
    """Every card of the file ``path`` and of the files it includes, in order."""
    items, _ = _read(Path(path))
    return [item for item in items if isinstance(item, Card)]


def read_deck_text(path: str | Path) -> DeckText:
    """The starter's and the engine's cards of the deck file ``path`` (see the module)."""
    items, notices = _read(Path(path))
    text = DeckText(notices=notices)
    begin = next((k for k, item in enumerate(items)
                  if isinstance(item, Card) and item.key(0) == "BEGIN"), None)  # fmt: skip
    ends_engine = [k for k, item in enumerate(items) if isinstance(item, _End) and item.engine]
    if begin is None:
        for item in items:
            if isinstance(item, _End):
                break
            text.engine.append(item)
        text.engine_block = bool(ends_engine)
        return text
    end = next((k for k in range(begin, len(items))
                if isinstance(items[k], _End) and not items[k].engine), len(items))  # fmt: skip
    text.starter = [item for item in items[begin:end] if isinstance(item, Card)]
    if any(isinstance(item, _End) for item in items[begin:end]):
        where = next(item.where for item in items[begin:end] if isinstance(item, _End))
        raise DeckError(f"{where}: /END/ENGINE inside the starter (after /BEGIN, before its "
                        "/END): a one-file deck holds the engine's cards, /END/ENGINE, then "
                        "/BEGIN and the starter's")  # fmt: skip
    before = [item for item in items[:begin] if isinstance(item, Card)]
    if before and not any(k < begin for k in ends_engine):
        first = before[0]
        raise DeckError(
            f"{first.header.where}: {first.name}: a card before /BEGIN: the starter file must "
            "begin with /BEGIN (a one-file deck: the engine's cards, then /END/ENGINE)"
        )
    after = [k for k in ends_engine if k > end]
    if before:
        text.engine, text.engine_block = before, True
        if after:
            raise DeckError(f"{items[after[0]].where}: a second /END/ENGINE: a one-file deck "
                            "holds one engine block")  # fmt: skip
    elif after:
        text.engine = [item for item in items[end + 1 : after[0]] if isinstance(item, Card)]
        text.engine_block = True
    else:
        ignored = [item for item in items[end + 1 :] if isinstance(item, Card)]
        if ignored:
            text.notices.append(
                f"{ignored[0].header.where}: {len(ignored)} cards after /END not read (Radioss "
                "reads nothing after /END)"
            )
    return text


def _read(path: Path) -> tuple[list, list[str]]:
    """The cards and /END markers of the file ``path`` and its includes, and notices."""
    reading = _Reading()
    reading.file(path, [])
    for item in reading.items:
        if isinstance(item, Card):
            while item.lines and not item.lines[-1].text.strip():
                item.lines.pop()
    items = [item for item in reading.items if not _submodel(item, reading.notices)]
    return items, reading.notices


def _submodel(item, notices: list[str]) -> bool:
    """Whether ``item`` is a //SUBMODEL card, read in place when it offsets no ID and has
    no units of its own (its cards are then the deck's), refused otherwise."""
    if not isinstance(item, Card) or item.parts[:2] != ["", "SUBMODEL"]:
        return False
    where = item.header.where
    if len(item.parts) > 3 and item.parts[3] not in ("", "0"):
        raise DeckError(f"{where}: {item.name}: unit_ID {item.parts[3]}: a submodel's own units "
                        "are not read; give its values in the units of /BEGIN")  # fmt: skip
    offsets = [w for line in item.lines[1:2] for w in line.words()]
    if any(_offset(w) for w in offsets):
        raise DeckError(f"{item.lines[1].where}: {item.name}: ID offsets ({' '.join(offsets)}) "
                        "are not read: write the submodel's cards with the deck's IDs")  # fmt: skip
    notices.append(f"{where}: {item.name}: read in place (no ID offsets, no units of its own)")
    return True


def _offset(word: str) -> bool:
    try:
        return parse_number(word, integer=True) != 0
    except NumberError:
        return True


class _Reading:
    """The state of reading a deck file and the files it includes."""

    def __init__(self):
        self.items: list = []
        self.notices: list[str] = []
        self.current: Card | None = None
        self.ended = False  # after the main file's /END: its text lines are not read

    def file(self, path: Path, stack: list[Path]) -> None:
        name = str(path)
        lines = self._text(path, stack)
        included = bool(stack)
        head: list[Line] = []  # an included file's lines before its first card
        at_head = True
        for number, line in enumerate(lines, start=1):
            first = line[:1]
            if first == " " or first == "\t":  # most data lines: look past the indent
                first = line.lstrip()[:1]
            if first == "#" or first == "$":  # a comment, #include or #enddata
                word = line.lstrip()[:8].lower()
                if word == "#include":
                    self._flush_head(head, included)
                    at_head = False
                    self._include(path, number, line.lstrip()[8:].strip(), stack)
                elif word == "#enddata":
                    break
                continue
            if line[:1] == "/":
                self._flush_head(head, included)
                at_head = False
                if not self._card(line.rstrip(), name, number, included):
                    return
                continue
            entry = Line(line, name, number)
            if at_head:
                head.append(entry)
            elif self.current is not None:
                self.current.lines.append(entry)
            elif line.strip() and not self.ended:
                self._header([entry])
        self._flush_head(head, included)

    def _card(self, line: str, name: str, number: int, included: bool) -> bool:
        """Start the card whose header is ``line``, or mark /END and /END/ENGINE; False
        when the file ends here (/END in an included file)."""
        body = line.strip()[2:] if line.startswith("//") else line.strip()[1:]
        parts = [p.strip() for p in body.rstrip("/").split("/")]
        if line.startswith("//"):  # //SUBMODEL, //ENDSUB
            parts.insert(0, "")
        upper = [p.upper() for p in parts]
        where = f"{name}:{number}"
        if upper == ["END"]:
            if included:
                self.notices.append(f"{where}: /END in an included file ends that file (as "
                                    "Radioss reads it)")  # fmt: skip
                return False
            self.items.append(_End(False, where))
            self.current, self.ended = None, True
        elif upper == ["END", "ENGINE"]:
            self.items.append(_End(True, where))
            self.current = None
        elif upper[:2] == ["", "ENDSUB"]:
            self.current = None
        else:
            self.current = Card(parts, Line(line, name, number))
            self.items.append(self.current)
        return True

    def _flush_head(self, head: list[Line], included: bool) -> None:
        """An included file's lines before its first card continue the including card, or
        are a free-text header (skipped); the main file's are a header."""
        if not head:
            return
        lines = list(head)
        head.clear()
        filled = [line for line in lines if line.text.strip()]
        if not filled:
            return
        if included and self.current is not None and _numbers(filled[0]):
            self.current.lines.extend(lines)
            return
        self._header(filled)

    def _header(self, lines: list[Line]) -> None:
        first, last = lines[0], lines[-1]
        span = f"{first.where}" if first is last else f"{first.where}-{last.number}"
        self.notices.append(
            f"{span}: {len(lines)} line{'s' if len(lines) > 1 else ''} of text outside any card "
            f"(a header: {first.text.strip()[:40]!r}) skipped"
        )

    def _include(self, path: Path, number: int, target: str, stack: list[Path]) -> None:
        target = target.strip().strip("'\"")
        where = f"{path}:{number}"
        if not target:
            raise DeckError(f"{where}: #include: no file named")
        included = (path.parent / target).resolve()
        if included in stack or included == path.resolve():
            raise DeckError(f"{where}: #include {target}: includes itself")
        if not included.is_file():
            raise DeckError(f"{where}: #include {target}: file not found")
        self.file(included, [*stack, path.resolve()])

    def _text(self, path: Path, stack: list[Path]) -> list[str]:
        """The lines of the file ``path`` (see the module for encodings and line ends)."""
        name = str(path)
        try:
            data = path.read_bytes()
        except OSError as err:
            where = f"{stack[-1]}: " if stack else ""
            raise DeckError(f"{where}{name}: cannot read the deck file: {err.strerror}") from None
        if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
            text = data.decode("utf-16", errors="replace")
        else:
            if b"\0" in data:
                at = data.index(b"\0")
                raise DeckError(f"{name}: not a text file (binary data at byte {at})")
            try:
                text = data.decode("utf-8-sig")
            except UnicodeDecodeError:
                text = data.decode("latin-1")
        lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        odd = []
        if not text.isascii() and _ODD_SPACES.search(text):
            odd = [(k, m) for k, line in enumerate(lines, start=1)
                   for m in [_ODD_SPACES.search(line)] if m]  # fmt: skip
        if odd:
            k, m = odd[0]
            what = _NAMES.get(m[0], "a Unicode space")
            more = f" ({len(odd)} lines hold such spaces)" if len(odd) > 1 else ""
            self.notices.append(f"{name}:{k}: {what} (U+{ord(m[0]):04X}) at column "
                                f"{m.start() + 1} read as a space{more}")  # fmt: skip
            lines = [_ODD_SPACES.sub(" ", line) for line in lines]
        return lines


def _numbers(line: Line) -> bool:
    """Whether every word of ``line`` reads as a number (data, rather than a header)."""
    try:
        for word in line.words():
            if word:
                parse_number(word)
    except NumberError:
        return False
    return True
