"""The engine's run controls: /RUN (the end time), /DT (the step's scale and floor, and
what happens below it: /DT/BRICK/STOP, DEL and CST, /DT/NODA/...), /ANIM/DT (frames),
/TFILE (history rows), in the deck's work units; /DT and /DEL of elements the deck
does not have are noticed and skipped."""

from __future__ import annotations

from rwall_fem.radioss.model import GROUP_CELLS, Deck
from rwall_fem.radioss.reader import Card, Line, read_fields

__all__ = ["ENGINE", "finish"]

# /DT/<element type>/<keyword>: the run's action below Tmin.
_ACTIONS = {"STOP": "stop", "DEL": "erode", "CST": "mass_scaling", "CST1": "mass_scaling",
            "CST2": "mass_scaling"}  # fmt: skip
# Radioss's element types and the cells of the deck that are theirs.
_ELEMENT_TYPES = {"BRICK": GROUP_CELLS["GRBRIC"], "SHELL": GROUP_CELLS["GRSHEL"],
                  "SH_3N": GROUP_CELLS["GRSH3N"], "SH3N": GROUP_CELLS["GRSH3N"]}  # fmt: skip
_OTHER_TYPES = ("INTER", "BEAM", "TRUSS", "SPRING", "QUAD", "AIRBAG", "SPH", "SMSTR", "FXBODY",
                "CNODE", "TRIA")  # fmt: skip


def _free(card: Card, layout: str, what: str) -> list:
    """The numbers of the card's first line by ``layout``: its words in order (the
    engine's lines are read in the free format, blanks separating the fields)."""
    line = card.line(0, what)
    words = line.words()
    free = Line(", ".join(words) + ",", line.file, line.number)  # a comma: the free format
    return read_fields(card, free, layout)


def _run(deck: Deck, card: Card) -> None:
    if deck.end_time is not None:
        card.fail("a second /RUN")
    (end,) = _free(card, "f:Tstop", "Tstop")
    if end <= 0:
        card.fail(f"Tstop = {end:g}: the end time is > 0", card.lines[0])
    deck.end_time = end * deck.work_units.time


def _time_step(deck: Deck, card: Card) -> None:
    """/DT, /DT/<element type>/<keyword>/<Iflag>, /DT/NODA/<keyword>/<Iflag>."""
    keys = [card.key(k) for k in range(1, len(card.parts))]
    words = [k for k in keys if not k.isdigit()]
    scale, floor = _free(card, "f:dTsca f:Tmin", "dTsca Tmin")
    if not 0.0 <= scale <= 1.0:
        card.fail(f"dTsca = {scale:g}: the time-step scale is in (0, 1]", card.lines[0])
    floor *= deck.work_units.time
    entry = {"card": card, "scale": scale or None, "floor": floor}
    if not words:
        deck.pending.setdefault("DT", []).append(entry | {"kind": "global"})
        return
    element = words[0]
    action = words[1] if len(words) > 1 else ""
    if element == "NODA":
        if action in ("", "SET"):
            how = ("Radioss's nodal time step: rwall_fem's step is its cells' stable step"
                   if not action else "SET (stiffness reduction) has no counterpart: read as "
                   "/DT/NODA/STOP, the run stopping below Tmin")  # fmt: skip
            (deck.notice if not action else deck.warn)(card, how)
            action = "STOP" if action == "SET" else ""
        if action and action not in _ACTIONS:
            card.fail(f"{action}: /DT/NODA/ takes CST, CST1, CST2, SET or STOP")
        deck.pending.setdefault("DT", []).append(entry | {"kind": "NODA", "action": action})
        return
    cells = _ELEMENT_TYPES.get(element)
    if cells is None and element not in _OTHER_TYPES:
        card.fail(f"{element}: the time-step control of /DT/<type>/ is for BRICK, SHELL, SH_3N, "
                  f"NODA, INTER and Radioss's other element types")  # fmt: skip
    if action and action not in _ACTIONS:
        card.fail(f"{action}: /DT/{element}/ takes STOP, DEL, CST (CST1, CST2)")
    held = cells is not None and any(b.cell in cells for b in deck.bodies)
    if not held:
        what = "interfaces" if element == "INTER" else f"{element} elements"
        deck.notice(card, f"skipped: the deck has no {what} rwall_fem reads")
        return
    deck.pending.setdefault("DT", []).append(entry | {"kind": element, "action": action})


def finish(deck: Deck) -> None:
    """The run's step controls from the /DT cards: the scale of the brick control (else
    the nodal one, else /DT), and what happens below its Tmin (/DT's: the run stops)."""
    entries = deck.pending.get("DT", [])
    overall = [e for e in entries if e["kind"] == "global"]
    controls = [e for e in entries if e["kind"] != "global"]
    control = next((e for e in controls if e["kind"] == "BRICK"), None)
    control = control or next((e for e in controls if e["kind"] == "NODA"), None)
    for e in controls:
        if e is not control:
            deck.warn(e["card"], f"not used: {control['card'].name} "
                      f"({control['card'].header.where}) controls the step")  # fmt: skip
    base = control or (overall[-1] if overall else None)
    if base is None:
        return
    deck.dt_scale = base["scale"] or (overall[-1]["scale"] if overall else None)
    action = base.get("action", "STOP" if base is not control else "")
    if base["floor"] > 0 and action:
        deck.dt_min, deck.dt_min_action = base["floor"], _ACTIONS[action]
    elif action in ("DEL", "CST", "CST1", "CST2"):
        card = base["card"]
        card.fail(f"Tmin = 0: {action} acts below Tmin, which must be above 0", card.lines[0])


def _animation(deck: Deck, card: Card) -> None:
    start, interval = _free(card, "f:Tstart f:Tfreq", "Tstart Tfreq")
    if interval <= 0:
        card.fail(f"Tfreq = {interval:g}: the interval is > 0", card.lines[0])
    time = deck.work_units.time
    deck.animation = (start * time, interval * time)


def _history(deck: Deck, card: Card) -> None:
    (interval,) = _free(card, "f:dt_his", "dt_his")
    deck.history_interval = interval * deck.work_units.time if interval > 0 else None


def _delete(deck: Deck, card: Card) -> None:
    """/DEL/<type>: elements deleted from the start of a run."""
    element = card.key(1)
    cells = _ELEMENT_TYPES.get(element)
    if cells is None or not any(b.cell in cells for b in deck.bodies):
        deck.notice(card, f"skipped: the deck has no {element} elements rwall_fem reads")
        return
    card.fail("deleting elements from the engine (/DEL) is not read; remove them from the "
              "starter's deck")  # fmt: skip


ENGINE = {"RUN": _run, "DT": _time_step, "ANIM/DT": _animation, "TFILE": _history,
          "DEL": _delete}  # fmt: skip
