"""Radioss decks (starter ``NAME_0000.rad`` and engine ``NAME_0001.rad``) as scenes.

A deck is read into a :class:`~rwall_fem.radioss.model.Deck` in SI units
(:func:`read_deck`: :mod:`~rwall_fem.radioss.reader` cuts it into cards,
:mod:`~rwall_fem.radioss.starter` and :mod:`~rwall_fem.radioss.engine` read them),
which becomes the raw table of a scene and a gmsh mesh file
(:mod:`~rwall_fem.radioss.to_scene`, with :mod:`~rwall_fem.radioss.materials` and
:mod:`~rwall_fem.radioss.parts`; :mod:`~rwall_fem.radioss.mesh`). From there
everything is a scene's: :func:`load_deck` validates it as a TOML file is validated,
and :func:`convert` writes the TOML and the mesh for users who continue in that format.

Every refusal is a :class:`DeckError` (a :class:`~rwall_fem.scene.SceneError`) of one
line naming the file, the line, the card and what is allowed; cards that only ask for
Radioss's own outputs are skipped with one warning line each. The cards and how they
map: ``docs/radioss.md``.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from rwall_fem.radioss.engine import read_engine
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import DeckError, read_cards
from rwall_fem.radioss.starter import read_starter
from rwall_fem.radioss.to_scene import SceneParts, scene_of
from rwall_fem.radioss.toml_text import toml_text

__all__ = ["DeckError", "convert", "engine_file", "is_deck", "load_deck", "read_deck"]

log = logging.getLogger("rwall_fem")


def is_deck(path: str | Path) -> bool:
    """Whether ``path`` names a Radioss starter file (``*.rad``)."""
    return Path(path).suffix.lower() == ".rad"


def engine_file(starter: Path) -> Path:
    """The engine file beside the starter: ``NAME_0000.rad`` -> ``NAME_0001.rad``."""
    stem = starter.stem
    if not stem.endswith("_0000"):
        raise DeckError(
            f"{starter}: a starter file is named NAME_0000.rad (its engine file NAME_0001.rad)"
        )
    return starter.with_name(stem[: -len("0000")] + "0001" + starter.suffix)


def read_deck(path: str | Path) -> Deck:
    """The starter file ``path`` and its engine file, read and checked, in SI."""
    starter = Path(path)
    if not starter.is_file():
        raise DeckError(f"{starter}: deck file not found")
    engine = engine_file(starter)
    if not engine.is_file():
        raise DeckError(f"{engine}: engine file not found: it gives /RUN (the end time)")
    deck = Deck(starter=starter, engine=engine)
    read_starter(deck, read_cards(starter))
    read_engine(deck, read_cards(engine))
    return deck


def _cache_dir() -> Path:
    """Where the meshes of decks are kept: ``$RWALL_FEM_CACHE/decks`` or
    ``$XDG_CACHE_HOME/rwall_fem/decks`` (``~/.cache`` by default)."""
    if "RWALL_FEM_CACHE" in os.environ:
        return Path(os.environ["RWALL_FEM_CACHE"]) / "decks"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "rwall_fem" / "decks"


def _prepare(path: Path, mesh_dir: Path | None) -> tuple[dict, list[str], list[str]]:
    """Read the deck and write its mesh (once: the cache is keyed by the mesh's content);
    the raw scene with ``mesh.file`` set, the warnings and the facts."""
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
    parts.raw["mesh"] = {"file": str(mesh.resolve())}
    return parts.raw, deck.warnings, parts.facts


def load_deck(path: str | Path, overrides=(), comm=None):
    """The :class:`~rwall_fem.scene.Scene` of the deck whose starter file is ``path``
    (``--set`` ``overrides`` applied as to a TOML scene), its mesh written to the cache.

    Rank 0 reads the deck; a refusal reaches every rank of ``comm`` (default
    ``MPI.COMM_WORLD``) as the same :class:`DeckError`. What the deck became and its
    warnings go to the ``rwall_fem`` logger, one line each."""
    from mpi4py import MPI

    from rwall_fem.scene import apply_override, parse_scene

    comm = MPI.COMM_WORLD if comm is None else comm
    path = Path(path)
    outcome = None
    if comm.rank == 0:
        try:
            outcome = ("ok", *_prepare(path, None))
        except DeckError as err:
            outcome = ("error", str(err))
    outcome = comm.bcast(outcome, root=0)
    if outcome[0] == "error":
        raise DeckError(outcome[1])
    _, raw, warnings, facts = outcome
    for line in facts:
        log.info("deck: %s", line)
    for line in warnings:
        log.warning("%s", line)
    for item in overrides:
        apply_override(raw, item, str(path))
    return parse_scene(raw, source=str(path), base=path.parent)


def convert(path: str | Path, directory: str | Path) -> Path:
    """Write the scene of the deck ``path`` as ``directory/NAME.toml`` beside its mesh
    ``NAME.msh`` (the TOML refers to it by its name); returns the TOML file. The scene is
    validated first, so a deck that cannot run writes nothing but the mesh."""
    from rwall_fem.scene import parse_scene

    path, directory = Path(path), Path(directory)
    name = path.stem.removesuffix("_0000")
    raw, warnings, facts = _prepare(path, directory)
    raw["mesh"] = {"file": f"{name}.msh"}
    parse_scene(raw, source=str(path), base=directory)
    header = "\n".join(
        [f"Converted by rwall_fem from the Radioss deck {path.name} (SI units).", "", *facts]
        + ([""] + [f"warning: {w}" for w in warnings] if warnings else [])
    )
    toml = directory / f"{name}.toml"
    toml.write_text(toml_text(raw, header), encoding="utf-8")
    return toml
