"""Radioss decks (starter ``NAME_0000.rad`` and engine ``NAME_0001.rad``) as scenes.

A deck is read into a :class:`~rwall_fem.radioss.model.Deck` in SI units
(:func:`read_deck`: :mod:`~rwall_fem.radioss.deck_files` cuts its files into cards,
whose fields :mod:`~rwall_fem.radioss.reader` reads; :mod:`~rwall_fem.radioss.starter`
and :mod:`~rwall_fem.radioss.engine` hand each card to the module of its family in
:mod:`~rwall_fem.radioss.cards`; :mod:`~rwall_fem.radioss.groups` works out what groups
and surfaces select),
which becomes the raw table of a scene and a gmsh mesh file
(:mod:`~rwall_fem.radioss.to_scene`, with :mod:`~rwall_fem.radioss.materials` and
:mod:`~rwall_fem.radioss.parts`; :mod:`~rwall_fem.radioss.mesh`). From there
everything is a scene's: :func:`load_deck` validates it as a TOML file is validated,
and :func:`convert` writes the TOML and the mesh for users who continue in that format.

Every refusal is a :class:`DeckError` (a :class:`~rwall_fem.scene.SceneError`) of one
line naming the file, the line, the card and what is allowed; control and output cards
with no counterpart here are skipped with one notice line each, and where the two codes
differ without a refusal, a warning line says how. The cards and how they map:
``docs/radioss.md``.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

from rwall_fem.radioss.deck_files import read_deck_text
from rwall_fem.radioss.engine import read_engine
from rwall_fem.radioss.listing import starter_listing
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import DeckError
from rwall_fem.radioss.starter import read_starter
from rwall_fem.radioss.to_scene import SceneParts, scene_of
from rwall_fem.radioss.toml_text import toml_text
from rwall_fem.radioss.units import units_text

__all__ = [
    "DeckError",
    "DeckReport",
    "convert",
    "engine_file",
    "is_deck",
    "load_deck",
    "read_deck",
]

log = logging.getLogger("rwall_fem")


def is_deck(path: str | Path) -> bool:
    """Whether ``path`` names a Radioss starter file (``*.rad``)."""
    return Path(path).suffix.lower() == ".rad"


def engine_file(starter: Path) -> Path:
    """The engine file beside the starter: ``NAME_0000.rad`` -> ``NAME_0001.rad``."""
    engine = _engine_beside(starter)
    if engine is None:
        raise DeckError(
            f"{starter}: a starter file is named NAME_0000.rad (its engine file NAME_0001.rad), "
            "unless it holds its engine's cards (a one-file deck)"
        )
    return engine


def read_deck(path: str | Path) -> Deck:
    """The deck whose starter file is ``path``, read and checked, in SI: the starter and
    the engine file beside it (``NAME_0001.rad``), or a one-file deck holding both."""
    starter = Path(path)
    if not starter.is_file():
        raise DeckError(f"{starter}: deck file not found")
    text = read_deck_text(starter)
    deck = Deck(starter=starter, notices=list(text.notices))
    if text.engine_block:
        deck.engine = starter
        engine_cards, engine_where = text.engine, starter
        beside = _engine_beside(starter)
        if beside is not None and beside.is_file():
            deck.notices.append(f"{beside}: not read: {starter.name} holds its engine's cards "
                                "(a one-file deck)")  # fmt: skip
    elif text.engine:
        first = text.engine[0]
        raise DeckError(f"{first.header.where}: {first.name}: a card before /BEGIN: the "
                        "starter file must begin with /BEGIN (a one-file deck: the engine's "
                        "cards, then /END/ENGINE)")  # fmt: skip
    else:
        engine = engine_file(starter)
        if not engine.is_file():
            raise DeckError(f"{engine}: engine file not found: it gives /RUN (the end time)")
        deck.engine = engine
        engine_text = read_deck_text(engine)
        if engine_text.starter:
            card = engine_text.starter[0]
            raise DeckError(f"{card.header.where}: /BEGIN in the engine file: it holds the "
                            "engine's cards (/RUN, /DT, ...)")  # fmt: skip
        deck.notices += engine_text.notices
        engine_cards, engine_where = engine_text.engine, engine
    read_starter(deck, text.starter)
    read_engine(deck, engine_cards, str(engine_where))
    return deck


def _engine_beside(starter: Path) -> Path | None:
    """``NAME_0001.rad`` beside ``NAME_0000.rad``; None for another name."""
    stem = starter.stem
    if not stem.endswith("_0000"):
        return None
    return starter.with_name(stem[: -len("0000")] + "0001" + starter.suffix)


def _cache_dir() -> Path:
    """Where the meshes of decks are kept: ``$RWALL_FEM_CACHE/decks`` or
    ``$XDG_CACHE_HOME/rwall_fem/decks`` (``~/.cache`` by default)."""
    if "RWALL_FEM_CACHE" in os.environ:
        return Path(os.environ["RWALL_FEM_CACHE"]) / "decks"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "rwall_fem" / "decks"


@dataclass
class DeckReport:
    """What a deck became: the raw scene (``mesh.file`` set), and the lines that say so:
    ``facts`` (what each card became), ``notices`` (what was skipped or read so),
    ``warnings`` (where the two codes differ); ``work_units`` the deck's (mass, length,
    time) sizes in SI and names, for ``output.units = "deck"``."""

    raw: dict
    facts: list[str]
    notices: list[str]
    warnings: list[str]
    work_units: tuple[tuple[float, float, float], tuple[str, str, str]]
    listing: list[str]  # a starter listing (:mod:`~rwall_fem.radioss.listing`)
    walls: list[str]  # each wall's card, in the order of the scene's walls

    def say(self) -> None:
        """Log the lines: facts and notices as information, warnings as warnings."""
        for line in self.facts:
            log.info("deck: %s", line)
        for line in self.notices:
            log.info("deck: notice: %s", line)
        for line in self.warnings:
            log.warning("%s", line)


def _prepare(path: Path, mesh_dir: Path | None, listing: bool = False) -> DeckReport:
    """Read the deck and write its mesh (once: the cache is keyed by the mesh's content);
    with ``listing``, work out its starter listing too."""
    deck = read_deck(path)
    parts: SceneParts = scene_of(deck)
    directory = Path(mesh_dir) if mesh_dir is not None else _cache_dir() / parts.mesh_key(deck)
    mesh = directory / f"{path.stem.removesuffix('_0000')}.msh"
    if mesh_dir is not None or not mesh.is_file():
        try:
            directory.mkdir(parents=True, exist_ok=True)
            parts.write_mesh(deck, mesh)
        except OSError as err:
            raise DeckError(f"{path}: cannot write the mesh file {mesh}: {err.strerror}") from None
    parts.raw["mesh"]["file"] = str(mesh.resolve())
    units = deck.work_units
    listing = starter_listing(deck, deck.dt_scale or 0.9) if listing else []
    walls = [f"/RWALL/{w.kind}/{w.id} ({w.where})" for w in deck.walls]
    sizes = ((units.mass, units.length, units.time), units.names)
    return DeckReport(parts.raw, parts.facts, deck.notices, deck.warnings, sizes, listing, walls)


def load_deck(path: str | Path, overrides=(), comm=None, *, report: list | None = None,
              listing: bool = False):  # fmt: skip
    """The :class:`~rwall_fem.scene.Scene` of the deck whose starter file is ``path``
    (``--set`` ``overrides`` applied as to a TOML scene), its mesh written to the cache.

    Rank 0 reads the deck; a refusal reaches every rank of ``comm`` (default
    ``MPI.COMM_WORLD``) as the same :class:`DeckError`. What the deck became, its notices
    and its warnings go to the ``rwall_fem`` logger, one line each, once the scene is
    valid; or, if ``report`` is a list, its :class:`DeckReport` is appended to it, for
    the caller to say when the run is built (so that an error is the only line), with
    a starter listing if ``listing`` (``rwall-fem check``)."""
    from mpi4py import MPI

    from rwall_fem.scene import apply_override, parse_scene

    comm = MPI.COMM_WORLD if comm is None else comm
    path = Path(path)
    outcome = None
    if comm.rank == 0:
        try:
            outcome = _prepare(path, None, listing)
        except DeckError as err:
            outcome = str(err)
    outcome = comm.bcast(outcome, root=0)
    if isinstance(outcome, str):
        raise DeckError(outcome)
    raw = outcome.raw
    _history_overridden(raw, overrides)
    for item in overrides:
        apply_override(raw, item, str(path))
    deck_units(raw, outcome.work_units, str(path))
    scene = parse_scene(raw, source=str(path), base=path.parent)
    if report is None:
        outcome.say()
    else:
        report.append(outcome)
    return scene


def _history_overridden(raw: dict, overrides) -> None:
    """A ``--set`` of ``output.history_interval`` (steps) or ``output.history_time`` (s)
    replaces what the deck gave of the other (/TFILE's time, or a row every step)."""
    given = {item.partition("=")[0].strip() for item in overrides}
    output = raw.get("output", {})
    for key, other in (("history_interval", "history_time"), ("history_time", "history_interval")):
        if f"output.{key}" in given:
            output.pop(other, None)


def deck_units(raw: dict, work_units, source: str) -> None:
    """``output.units = "deck"`` (a ``--set`` on a deck) becomes the deck's work units."""
    output = raw.get("output")
    if isinstance(output, dict) and output.get("units") == "deck":
        sizes, names = work_units
        output["units"] = units_text(sizes, names)


def convert(path: str | Path, directory: str | Path, force: bool = False) -> Path:
    """Write the scene of the deck ``path`` as ``directory/NAME.toml`` beside its mesh
    ``NAME.msh`` (the TOML refers to it by its name); returns the TOML file. The scene is
    validated first, so a deck that cannot run writes nothing but the mesh. A folder that
    holds a NAME.toml or NAME.msh already is refused, unless ``force``."""
    from rwall_fem.scene import parse_scene

    path, directory = Path(path), Path(directory)
    name = path.stem.removesuffix("_0000")
    toml = directory / f"{name}.toml"
    if not force:
        for target in (toml, directory / f"{name}.msh"):
            if target.exists():
                raise DeckError(f"{target}: exists; convert does not overwrite a scene: give "
                                "another folder, or --force to replace it")  # fmt: skip
    outcome = _prepare(path, directory)
    raw = outcome.raw
    raw["mesh"]["file"] = f"{name}.msh"
    parse_scene(raw, source=str(path), base=directory)
    lines = [*outcome.facts, *(f"notice: {n}" for n in outcome.notices)]
    header = "\n".join(
        [f"Converted by rwall_fem from the Radioss deck {path.name} (SI units).", "", *lines]
        + ([""] + [f"warning: {w}" for w in outcome.warnings] if outcome.warnings else [])
    )
    toml.write_text(toml_text(raw, header), encoding="utf-8")
    return toml
