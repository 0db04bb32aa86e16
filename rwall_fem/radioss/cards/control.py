"""Control and output cards of the starter and the engine: read where they change the
model (/DEF_SOLID and /DEF_SHELL give the blank fields of properties their values,
/RANDOM is the mesh's coordinate noise), skipped with one notice line each where they
have no counterpart here (Radioss's own outputs, its parallel and memory settings)."""

from __future__ import annotations

from rwall_fem.radioss.cards.base import notice_only
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card

__all__ = ["ENGINE", "STARTER"]

# Cards with no counterpart here: why each is skipped.
_OUTPUT = "Radioss's own output"
_SETTINGS = {
    "ANALY": "analysis flags (3D analysis, parith, subcycling): rwall_fem's are fixed",
    "ARCH": "architecture flags",
    "IOFLAG": "Radioss's listing and file options",
    "SPMD": "Radioss's domains and threads: rwall_fem runs on the ranks mpirun gives it",
    "MEMORY": "Radioss's memory setting",
    "SHFRA": "the shells' local frame (the deck has no shell rwall_fem reads)",
    "PARITH": "Radioss's parallel arithmetic: rwall_fem's sums do not depend on the ranks "
    "beyond round-off",
    "PROC": "Radioss's processor count",
    "TITLE": "the run's title",
    "VERS": "Radioss's version of its outputs",
    "TH": _OUTPUT, "ANIM": _OUTPUT, "OUTP": _OUTPUT, "H3D": _OUTPUT, "STATE": _OUTPUT,
    "PRINT": _OUTPUT, "RFILE": "Radioss's restart files (rwall_fem: output.checkpoint_steps)",
    "MON": "Radioss's memory and time monitor",
    "ATFILE": _OUTPUT, "@TFILE": _OUTPUT, "ABF": _OUTPUT, "DYNAIN": _OUTPUT,
    "ACCEL": "an accelerometer (an output of Radioss's time histories)",
    "SECT": "a section (section forces are an output of Radioss's time histories)",
    "SKEW": "a skew frame: a card that refers to one is refused",
    "FRAME": "a frame: a card that refers to one is refused",
    "SENSOR": "a sensor: a card that refers to one is refused",
    "CHECK": "Radioss's restart-file check",
    "DTIX": "the largest first step: rwall_fem's first step is the stable step at rest",
    "STOP": "Radioss's stops on energy and mass errors: rwall_fem's guards are "
    "run.max_energy_error and run.max_added_mass",
}  # fmt: skip


@notice_only
def _skip(deck: Deck, card: Card) -> None:
    deck.notice(card, f"skipped: {_SETTINGS[card.key(0)]}")


@notice_only
def _title(deck: Deck, card: Card) -> None:
    text = card.title()
    deck.notice(card, f"the title {text!r}: skipped" if text else "skipped: the run's title")


def _random(deck: Deck, card: Card) -> None:
    """/RANDOM: noise of amplitude Anoise on every node coordinate (mesh.noise)."""
    amplitude, seed = card.read_optional(0, "f:Anoise f:Seed")
    if card.key(1) == "GRNOD" and amplitude:
        deck.warn(card, "noise on a node group only: rwall_fem's mesh.noise moves every node; "
                  "not applied")  # fmt: skip
        return
    if amplitude == 0:
        deck.notice(card, "no noise (Anoise 0)")
        return
    if amplitude < 0:
        card.fail(f"Anoise = {amplitude:g}: a noise amplitude is >= 0", card.lines[0])
    deck.noise = (amplitude * deck.input_units.length, int(abs(seed)) % 2**64)
    deck.notice(card, f"coordinate noise of {deck.noise[0]:g} m, seed {deck.noise[1]}: "
                "mesh.noise (rwall_fem's own random numbers)")  # fmt: skip


_SOLID_DEFAULTS = "i:isolid i:ismstr i:icpre -:blank i:itetra4 i:itetra10 i:imas i:iframe"
_SHELL_DEFAULTS = ("i:ishell i:ismstr i:ithick i:iplas i:istrain i:ioffset -:blank i:ish3n "
                   "i:idrill")  # fmt: skip


def _defaults(deck: Deck, card: Card) -> None:
    """/DEF_SOLID, /DEF_SHELL: the values of the blank fields of /PROP/SOLID and
    /PROP/SHELL (their families apply them)."""
    solid = card.key(0) == "DEF_SOLID"
    layout = _SOLID_DEFAULTS if solid else _SHELL_DEFAULTS
    names = [w.split(":")[1] for w in layout.split() if not w.startswith("-")]
    values = card.read_optional(0, layout)
    table = deck.solid_defaults if solid else deck.shell_defaults
    table.update({k: v for k, v in zip(names, values, strict=True) if v})
    given = ", ".join(f"{k.capitalize()} {v}" for k, v in table.items())
    deck.notice(card, f"defaults of blank property fields: {given or 'none given'}")


STARTER = {key: _skip for key in ("ANALY", "ARCH", "IOFLAG", "SPMD", "MEMORY", "SHFRA", "TH",
                                  "ANIM", "H3D", "PRINT", "ACCEL", "SECT", "SKEW", "FRAME",
                                  "SENSOR", "CHECK", "STOP", "OUTP", "RFILE", "STATE")}  # fmt: skip
STARTER |= {"TITLE": _title, "RANDOM": _random, "DEF_SOLID": _defaults, "DEF_SHELL": _defaults}
ENGINE = {key: _skip for key in ("ANIM", "TH", "OUTP", "H3D", "STATE", "PRINT", "RFILE", "VERS",
                                 "MON", "PARITH", "PROC", "ATFILE", "@TFILE", "ABF", "DYNAIN",
                                 "DTIX", "STOP")}  # fmt: skip
ENGINE |= {"TITLE": _title}
