"""The engine file's cards: the end time, the time-step scale and floor, the animation
and time-history intervals. Engine values are in the deck's work units (/BEGIN) and in
the free format (numbers separated by blanks)."""

from __future__ import annotations

from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card, DeckError, parse_number

__all__ = ["read_engine"]

_OUTPUT = ("TH", "ANIM", "PRINT", "VERS", "RFILE", "STATE", "OUTP", "H3D", "MON")
_SUPPORTED = "/RUN, /DT, /ANIM/DT, /TFILE (and, skipped with a warning, output cards)"


def _numbers(card: Card, count: int, what: str) -> list[float]:
    line = card.line(0, what)
    words = line.words()
    try:
        values = [parse_number(w) for w in words[:count]]
    except ValueError:
        card.fail(f"cannot read {line.text.strip()!r} as {what}", line)
    return values + [0.0] * (count - len(values))


def read_engine(deck: Deck, cards: list[Card]) -> None:
    """Fill the run controls of ``deck`` (seconds) from the engine's ``cards``."""
    time = deck.work_units.time
    for card in cards:
        kind = card.key(0)
        if kind == "RUN":
            (end,) = _numbers(card, 1, "Tstop")
            if end <= 0:
                card.fail(f"Tstop = {end:g}: the end time is > 0", card.lines[0])
            deck.end_time = end * time
        elif kind == "DT" and len(card.parts) == 1:
            scale, floor = _numbers(card, 2, "scale Tmin")
            if not 0.0 <= scale <= 1.0:
                card.fail(f"scale = {scale:g}: the time-step scale is in (0, 1]", card.lines[0])
            deck.dt_scale = scale or None
            deck.dt_min = floor * time if floor > 0 else None
        elif kind == "ANIM" and card.key(1) == "DT":
            start, interval = _numbers(card, 2, "Tstart Tfreq")
            if interval <= 0:
                card.fail(f"Tfreq = {interval:g}: the interval is > 0", card.lines[0])
            deck.animation = (start * time, interval * time)
        elif kind == "TFILE":
            (interval,) = _numbers(card, 1, "dt_his")
            deck.history_interval = interval * time if interval > 0 else None
        elif kind in _OUTPUT or kind == "STOP":
            what = "asks for Radioss's own output" if kind != "STOP" else (
                "not read: rwall_fem's guard is run.max_energy_error"
            )  # fmt: skip
            deck.warnings.append(f"{card.header.where}: {card.name}: skipped ({what})")
        else:
            card.fail(f"unsupported engine card; the engine cards read are {_SUPPORTED}")
    if deck.end_time is None:
        raise DeckError(f"{deck.engine}: no /RUN card: it gives the end time (Tstop)")
