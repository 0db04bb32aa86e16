"""The TYPE7 fields that shape the variable gap and bound the penalty stiffness, read
where Radioss reads them (``hm_read_inter_type07.F``): Fscalegap and Gap_max with Igap 2
and 3, %mesh_size with Igap 3, Stmin and Stmax with Istf 2 to 5. A deck with them gives
the [[contact]] a scene would write for the same interface (gap_scale, gap_max,
gap_size_share, stiffness_min, stiffness_max); where Radioss leaves a field out, one
warning line says so; a bad value is one line naming the field.

The deck is ``test_deck_contacts``'s plate in self-contact, in kg-mm-ms: a length of 1 is
1 mm, a stiffness of 1 is 1 kN/mm = 1e6 N/m.
"""

import logging

import pytest
from mpi4py import MPI

from rwall_fem import build_simulation
from rwall_fem.radioss import DeckError, load_deck
from rwall_fem.scene.schema import ContactSpec

from .test_deck_contacts import field, tube

comm = MPI.COMM_WORLD


def _set(*fields):
    """An edit writing ``(row, column, text)`` into the /INTER/TYPE7 card."""

    def edit(lines, k):
        for row, start, text in fields:  # integers 10 wide, reals 20
            field(lines, k, row, start, text.rjust(10 if row == 1 or start >= 80 else 20))

    return edit


IGAP = lambda v: (1, 40, str(v))  # noqa: E731
ISTF = lambda v: (1, 20, str(v))  # noqa: E731
FSCALE = lambda v: (2, 0, str(v))  # noqa: E731
GAPMAX = lambda v: (2, 20, str(v))  # noqa: E731
STMIN = lambda v: (3, 0, str(v))  # noqa: E731
STMAX = lambda v: (3, 20, str(v))  # noqa: E731
MESH = lambda v: (3, 40, str(v))  # noqa: E731
IREM = lambda v: (3, 80, str(v))  # noqa: E731


def load(shared_dir, caplog, *fields):
    """The deck's one contact and the warning lines of its interface."""
    log = logging.getLogger("rwall_fem")  # as test_deck_contacts: the command line, run
    log.addHandler(caplog.handler)  # in-process by other tests, stops it propagating
    try:
        with caplog.at_level("WARNING", logger="rwall_fem"):
            (contact,) = load_deck(tube(shared_dir, _set(*fields))).contacts
    finally:
        log.removeHandler(caplog.handler)
    # once each: the handler added and the root's (when the logger propagates) both see it
    said = dict.fromkeys(r.getMessage() for r in caplog.records)
    return contact, [s for s in said if "/INTER/TYPE7/1" in s]


SELF = dict(single_surface=True)


@pytest.mark.parametrize(
    "fields, scene",
    [
        ([IGAP(3), FSCALE(0.5), GAPMAX(0.4), MESH(0.3)],
         ContactSpec(**SELF, gap_scale=0.5, gap_max=4e-4, gap_size_share=0.3)),
        ([IGAP(2), FSCALE(0.5), GAPMAX(0.4)],
         ContactSpec(**SELF, gap_scale=0.5, gap_max=4e-4)),
        ([IGAP(3)], ContactSpec(**SELF)),  # blank: 1, no bound, 0.4
        ([ISTF(2), STMIN(10), STMAX(300)],
         ContactSpec(**SELF, gap=1e-3, stiffness_min=1e7, stiffness_max=3e8)),
        ([ISTF(4), STMIN(10)], ContactSpec(**SELF, gap=1e-3, stiffness_min=1e7)),
        ([IREM(2)], ContactSpec(**SELF, gap=1e-3, exclude_within_gap=True)),
        ([IGAP(3), IREM(2)], ContactSpec(**SELF, exclude_within_gap=True)),
    ],
    ids=["igap3", "igap2", "igap3-blank", "istf2-bounds", "istf4-min", "irem2", "irem2-igap3"],
)
def test_the_deck_gives_the_scene_contact(fields, scene, shared_dir, caplog):
    contact, said = load(shared_dir, caplog, *fields)
    _same(contact, scene)
    assert not any("left out" in s or "Igap = 2" in s or "Irem_gap" in s for s in said), said


def _same(a: ContactSpec, b: ContactSpec) -> None:
    """Equal, the lengths and stiffnesses to round-off of the unit conversion."""
    for name in ContactSpec.__dataclass_fields__:
        x, y = getattr(a, name), getattr(b, name)
        if isinstance(x, float) and isinstance(y, float):
            assert x == pytest.approx(y, rel=1e-12), name
        else:
            assert x == y, name


@pytest.mark.parametrize(
    "fields, line, check",
    [
        ([IGAP(1), FSCALE(0.5)], "Fscalegap = 0.5: left out: Radioss reads it with Igap 2 "
         "and 3 only (Igap = 1)", lambda c: c.gap_scale == 1.0),
        ([GAPMAX(0.4)], "Gap_max = 0.4: left out", lambda c: c.gap_max is None),
        ([IGAP(2), MESH(0.3)], "%mesh_size = 0.3: left out: Radioss reads it with Igap 3 only",
         lambda c: c.gap_size_share == 0.4),
        ([STMAX(300)], "Stmax = 300: left out: Radioss reads it with Istf 2 to 5 only",
         lambda c: c.stiffness_max is None),
    ],
    ids=["fscale-igap1", "gapmax-igap0", "mesh-igap2", "stmax-istf0"],
)
def test_fields_radioss_leaves_out_give_one_line(fields, line, check, shared_dir, caplog):
    contact, said = load(shared_dir, caplog, *fields)
    assert check(contact)
    assert sum(line in s for s in said) == 1, said
    assert all("\n" not in s for s in said)


@pytest.mark.parametrize(
    "fields, message",
    [
        ([IGAP(3), GAPMAX(-1)], "Gap_max = -1: the largest gap is > 0"),
        ([IGAP(3), FSCALE(-0.5)], "Fscalegap = -0.5: the gap scale is > 0"),
        ([IGAP(3), MESH(1.5)], "%mesh_size = 1.5: the share of the shortest side is in (0, 1]"),
        ([ISTF(2), STMIN(-1)], "Stmin = -1, Stmax = 0: the bounds of the stiffness are >= 0"),
        ([ISTF(2), STMIN(10), STMAX(5)], "Stmin = 10 is above Stmax = 5"),
    ],
    ids=["gapmax", "fscale", "mesh", "stmin", "crossed"],
)
def test_bad_values_are_one_line(fields, message, shared_dir):
    with pytest.raises(DeckError) as caught:
        load_deck(tube(shared_dir, _set(*fields)))
    said = str(caught.value)
    assert message in said and "\n" not in said and "model_0000.rad:" in said


def test_the_deck_builds_the_bounded_interface(shared_dir):
    """Built: the floor min(Fscalegap x t, h / 2) = 0.5 mm is the gap (each share
    min(0.5 x 0.5, 0.3 x 5) = 0.25 mm, the pair min(0.5, Gap_max 0.4) = 0.4 mm below it:
    Gap_max does not lower the floor), k0 = E t = 2.1e8 N/m bounded by Stmax 100 kN/mm =
    1e8 N/m."""
    fields = [IGAP(3), FSCALE(0.5), GAPMAX(0.4), MESH(0.3), ISTF(2), STMAX(100)]
    scene = load_deck(tube(shared_dir, _set(*fields)))
    (interface,) = build_simulation(scene, comm, shared_dir / "built").contacts
    assert interface.gap == pytest.approx(5e-4, rel=1e-12)
    assert interface.gap_max == pytest.approx(5e-4, rel=1e-12)
    assert interface.k0_range == pytest.approx((1e8, 1e8), rel=1e-12)
    assert interface.shell_half == pytest.approx(2.5e-4, rel=1e-12)  # each share


def test_a_solid_deck_leaves_the_shells_gap_fields_out(shared_dir, caplog):
    """A self-contact of solids (the bar of ``test_bad_decks``) with Igap 3, Fscalegap,
    Gap_max and %mesh_size: a solid's face adds no thickness to the gap (Radioss's variable
    gap of solids is its floor), so the fields are left out with one warning line and the
    contact keeps the solids' gap; a scene giving them on solids is refused
    (``bad_scenes/354``)."""
    from .test_bad_decks import good, written
    from .test_deck_contacts import TYPE7

    d = good()
    d.cards += ["/SURF/PART/EXT/1" if c == "/SURF/PART/1" else c for c in TYPE7]

    def edit(lines):
        _set(IGAP(3), FSCALE(0.5), GAPMAX(0.4), MESH(0.3))(lines, lines.index("/INTER/TYPE7/1"))

    directory = shared_dir / "solid_gap"
    if comm.rank == 0:
        directory.mkdir(exist_ok=True)
    comm.Barrier()
    log = logging.getLogger("rwall_fem")
    log.addHandler(caplog.handler)
    try:
        with caplog.at_level("WARNING", logger="rwall_fem"):
            (contact,) = load_deck(written(d, directory, edit)).contacts
    finally:
        log.removeHandler(caplog.handler)
    said = [s for s in dict.fromkeys(r.getMessage() for r in caplog.records)
            if "Fscalegap, Gap_max, %mesh_size: left out" in s]  # fmt: skip
    assert len(said) == 1 and "\n" not in said[0], said
    assert (contact.gap, contact.gap_scale, contact.gap_max, contact.gap_size_share) == (
        None, 1.0, None, 0.4)
