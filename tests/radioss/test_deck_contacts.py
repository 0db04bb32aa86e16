"""Radioss decks with contact: /INTER/TYPE7 on /SURF and /GRNOD becomes the scene's
[[contact]] (``rwall_fem/radioss/contacts.py``), with Radioss's rules for what the deck
leaves blank; bad interfaces are refused in one line naming the file, the line and the
card, and each field not honoured gives one warning line.

The deck: the plate of shells of ``test_shell_decks`` (8 x 4 shells of 5 mm, 1 mm thick)
in self-contact, every field of TYPE7 at its default. Radioss's constant gap without
GAPmin (``i7sti3.F``): the mean thickness of the main shells, at most half their
shortest side: min(1, 2.5) mm here.
"""

import logging
import subprocess
import sys
from pathlib import Path

import pytest
from mpi4py import MPI

from rwall_fem import build_simulation
from rwall_fem.radioss import DeckError, load_deck
from rwall_fem.scene import SceneError

from .decks import f20, i10
from .test_shell_decks import plate_deck

comm = MPI.COMM_WORLD

TYPE7 = [
    "/SURF/PART/1", "the plate", i10(1),
    "/INTER/TYPE7/1", "self contact",
    i10(1) + i10(1) + i10(0) * 3 + " " * 10 + i10(0) * 4,
    f20(0.0) * 3 + " " * 20 + i10(0) * 2,
    f20(0.0) * 4 + i10(0) * 2,
    f20(0.0) * 5,
    "       000" + " " * 20 + i10(0) + f20(0.0) * 3,
    i10(0) * 2 + f20(0.0) + i10(0) * 3 + f20(0.0) + i10(0),
]  # fmt: skip


def tube(directory: Path, edit=None) -> Path:
    """The plate deck with self-contact, written by rank 0 (edited by ``edit(lines, k)``,
    k the index of the /INTER/TYPE7 line)."""
    d = plate_deck()
    d.cards += TYPE7
    path = None
    if comm.rank == 0:
        path = d.write(directory)
        if edit:
            lines = path.read_text().splitlines()
            edit(lines, lines.index("/INTER/TYPE7/1"))
            path.write_text("\n".join(lines) + "\n")
    return comm.bcast(path, root=0)


def field(lines, k, row, start, text):
    """Write ``text`` right-aligned into data line ``row`` of the card at ``k`` (its title
    is row 0; comment lines are skipped), from column ``start``."""
    rows = [i for i in range(k + 1, len(lines)) if not lines[i].startswith("#")]
    i = rows[row]
    width = len(text)
    line = lines[i].ljust(start + width)
    lines[i] = line[:start] + text + line[start + width :]


def test_a_self_contact_deck_takes_radioss_gap(shared_dir):
    scene = load_deck(tube(shared_dir))
    (contact,) = scene.contacts
    assert contact.single_surface and contact.main == ()  # the body is its one part
    assert contact.gap == pytest.approx(1e-3, rel=1e-12)  # min(t, h / 2)
    assert contact.stiffness_scale == 1.0 and contact.friction == 0.0
    assert contact.damping == pytest.approx(0.05)  # VIS_S blank: Radioss's 0.05


@pytest.mark.parametrize(
    "edit, check",
    [
        (lambda ls, k: field(ls, k, 1, 40, "1".rjust(10)), lambda c: c.gap is None),  # Igap 1
        (lambda ls, k: field(ls, k, 4, 0, "2.5".rjust(20)),
         lambda c: c.stiffness_scale == 2.5),
        (lambda ls, k: field(ls, k, 4, 20, "0.2".rjust(20)), lambda c: c.friction == 0.2),
        (lambda ls, k: field(ls, k, 4, 40, "0.8".rjust(20)),
         lambda c: c.gap == pytest.approx(8e-4, rel=1e-12)),  # GAPmin in mm
    ],
    ids=["igap1", "stfac", "fric", "gapmin"],
)
def test_type7_fields_map_onto_the_contact(edit, check, shared_dir):
    (contact,) = load_deck(tube(shared_dir, edit)).contacts
    assert check(contact)


def test_fields_not_honoured_give_one_line_each(shared_dir, caplog):
    def edit(lines, k):
        field(lines, k, 4, 60, "0.01".rjust(20))  # Tstart
        field(lines, k, 1, 20, "3".rjust(10))  # Istf 3: main and secondary's maximum

    log = logging.getLogger("rwall_fem")  # the command line, run in-process by other
    log.addHandler(caplog.handler)  # tests, stops it propagating to the root's handler
    try:
        with caplog.at_level("WARNING", logger="rwall_fem"):
            load_deck(tube(shared_dir, edit))
    finally:
        log.removeHandler(caplog.handler)
    said = [r.getMessage() for r in caplog.records if "/INTER/TYPE7/1" in r.getMessage()]
    assert any("Tstart = 0.01: not honoured" in s for s in said)
    assert any("Istf = 3: not honoured" in s for s in said)
    assert all("\n" not in s and "model_0000.rad:" in s for s in said)


def _no_segment(lines, k):
    at = lines.index("/SURF/PART/1")
    lines[at] = "/SURF/SEG/1"
    del lines[at + 2]


def _kind(kind):
    return lambda ls, k: ls.__setitem__(k, f"/INTER/{kind}/1")


@pytest.mark.parametrize(
    "edit, message",
    [
        (_kind("TYPE5"), "/INTER/TYPE5/1: interfaces of TYPE5 are not read: /INTER/TYPE7 is"),
        (_kind("TYPE3"), "/INTER/TYPE3/1: interfaces of TYPE3 are not read"),
        (_kind("TYPE24"), "interfaces of TYPE24 are not read; supported: /INTER/TYPE7"),
        (lambda ls, k: field(ls, k, 1, 10, "9".rjust(10)), "surf_IDm 9 refers to no /SURF"),
        (lambda ls, k: field(ls, k, 1, 0, "9".rjust(10)), "grnd_IDs 9 refers to no /GRNOD"),
        (lambda ls, k: field(ls, k, 4, 0, "-1".rjust(20)), "Stfac = -1: the stiffness scale"),
        (lambda ls, k: field(ls, k, 1, 20, "1".rjust(10)), "Istf = 1: a stiffness given"),
        (lambda ls, k: ls.__setitem__(ls.index("/SURF/PART/1") + 2, "         9"),
         "/SURF/PART/1: part 9 refers to no /PART"),
        (_no_segment, "surf_IDm 1 has no segment"),
    ],
    ids=["type5", "type3", "type24", "surface", "nodes", "stfac", "istf1", "unknown-part",
         "no-faces"],
)
def test_bad_interfaces_are_one_line(edit, message, shared_dir):
    with pytest.raises(DeckError) as caught:
        load_deck(tube(shared_dir, edit))
    said = str(caught.value)
    assert message in said and "\n" not in said and "model_0000.rad:" in said


def test_a_gap_larger_than_the_plate_is_refused_at_build(shared_dir):
    scene = load_deck(tube(shared_dir, lambda ls, k: field(ls, k, 4, 40, "30".rjust(20))))
    with pytest.raises(SceneError, match=r"contact\[0\]\.gap: 0\.03 m is not smaller than"):
        build_simulation(scene, comm, shared_dir / "out")


@pytest.mark.serial
def test_a_bad_interface_exits_2_in_one_line(tmp_path):
    path = tube(tmp_path, _kind("TYPE11"))
    done = subprocess.run([sys.executable, "-m", "rwall_fem", "check", str(path)],
                          capture_output=True, text=True)  # fmt: skip
    assert done.returncode == 2
    assert done.stderr.strip().count("\n") == 0 and "interfaces of TYPE11" in done.stderr
