"""Bad decks are refused in one line naming the file, the line and the card, with what is
allowed, on every rank and with no traceback (a DeckError, which the command line turns
into exit code 2 as any bad scene); cards that only ask for Radioss's outputs are skipped
with one warning line each."""

import codecs
import logging
import re
import subprocess
import sys

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.radioss import DeckError, load_deck, read_deck

from .decks import BarDeck


def good() -> BarDeck:
    d = BarDeck(units="kg-mm-ms", nz=2)
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    d.group(1, "PART", [1])
    d.initial_velocity((0, 0, -5.0), 1)
    d.wall("PLANE", m1=(0, 0, 1), dsearch=1.0)
    return d


def written(d: BarDeck, directory, edit=None):
    path = None
    if MPI.COMM_WORLD.rank == 0:
        path = d.write(directory)
        if edit:
            lines = path.read_text().splitlines()
            edit(lines)
            path.write_text("\n".join(lines) + "\n")
    return MPI.COMM_WORLD.bcast(path, root=0)


def line_of(lines, text, after=0):
    return next(i for i, line in enumerate(lines) if i >= after and line.startswith(text))


def cut_brick(lines):
    k = line_of(lines, "/BRICK") + 1
    lines[k] = lines[k][:60]


def bad_field(lines):
    k = line_of(lines, "/MAT/LAW1") + 3
    lines[k] = "           2.1.0e2" + lines[k][18:]


def dangling_mat(lines):
    k = line_of(lines, "/PART") + 3
    lines[k] = f"{1:10d}{7:10d}"


def no_material(lines):
    k = line_of(lines, "/PART") + 3
    lines[k] = f"{1:10d}{0:10d}"


def unsupported(lines):
    k = line_of(lines, "/PROP")
    lines[k:k] = ["/RBE2/1", "a rigid element", "         1         2"]


def unknown(lines):
    k = line_of(lines, "/PROP")
    lines[k:k] = ["/XYZ/1", "what", "         1         2"]


def isolid(lines):
    k = line_of(lines, "/PROP") + 2
    lines[k] = f"{16:10d}" + lines[k][10:]


def missing_line(lines):
    k = line_of(lines, "/RWALL")
    del lines[k + 5 :]


def long_node_id(lines):
    k = line_of(lines, "/NODE") + 1
    lines[k] = "12345678901234567890, 0.0, 0.0, 0.0"


def brick_id_twice(lines):
    k = line_of(lines, "/BRICK") + 2
    lines[k] = f"{1:10d}" + lines[k][10:]


def length_unit_inf(lines):
    k = line_of(lines, "/BEGIN") + 3
    lines[k] = f"{'kg':>20}{'inf':>20}{'ms':>20}"


def version_44(lines):
    lines[line_of(lines, "/BEGIN") + 2] = f"{44:10d}{0:10d}"


def version_90_units_by_cards(lines):
    k = line_of(lines, "/BEGIN")
    lines[k + 2 : k + 5] = [f"{90:10d}{0:10d}", "/UNIT/LENGTH/1", "/UNIT/MASS/1"]


def failure_strain_negative(lines):
    k = line_of(lines, "/MAT/LAW1")
    lines[k:k + 4] = ["/MAT/LAW2/1", "jc", f"{7.85e-6:20g}", f"{210:20g}{0.3:20g}",
                      f"{0.4:20g}{0.1:20g}{0.5:20g}{-0.2:20g}"]  # fmt: skip


def cap_below_yield(lines):
    k = line_of(lines, "/MAT/LAW1")
    lines[k:k + 4] = ["/MAT/LAW2/1", "jc", f"{7.85e-6:20g}", f"{210:20g}{0.3:20g}",
                      f"{0.4:20g}{0.1:20g}{0.5:20g}{0:20g}{0.3:20g}"]  # fmt: skip


def cap_after_the_rate_factor(lines):
    k = line_of(lines, "/MAT/LAW1")
    lines[k:k + 4] = ["/MAT/LAW2/1", "jc", f"{7.85e-6:20g}", f"{210:20g}{0.3:20g}",
                      f"{0.4:20g}{0.1:20g}{0.5:20g}{0:20g}{0.6:20g}",
                      f"{0.01:20g}{1e-3:20g}{2:10d}"]  # fmt: skip


def flat_brick(lines):
    """The top face of the first brick on its bottom face: its nodes 5-8 moved to z = 0
    (distinct node IDs, no node repeated)."""
    k = line_of(lines, "/BRICK") + 1
    top = [int(lines[k][10 * m : 10 * m + 10]) for m in range(5, 9)]
    first = line_of(lines, "/NODE") + 1
    for n, line in enumerate(lines[first:], start=first):
        if line.startswith("/"):
            break
        if int(line[:10]) in top:
            lines[n] = line[:50] + f"{0.0:20g}"


CASES = {
    # name: (edit, the card's header or line text, what the message says)
    "truncated line": (
        cut_brick, "/BRICK", r"truncated line: element 1 needs 8 node IDs, got 5"
    ),
    "field that does not parse": (
        bad_field, "/MAT/LAW1", r"field E \(columns 1-20\): cannot read '2.1.0e2"
    ),
    "ID that refers to nothing": (dangling_mat, "/PART", r"mat_ID 7 refers to no /MAT"),
    "part without a material": (no_material, "/PART", r"part 1 has no material"),
    "a card of physics not read": (
        unsupported, "/RBE2/1",
        r"/RBE2/1: kinematic conditions of this kind are not read: /BCS and /IMPVEL are; the "
        r"cards read: docs/radioss.md",
    ),
    "an unknown card": (
        unknown, "/XYZ/1", r"/XYZ/1: unsupported card; the starter cards read are /BEGIN, /UNIT",
    ),
    "unsupported Isolid": (isolid, "/PROP", r"Isolid = 16: supported: 24"),
    "truncated card": (
        missing_line, "/RWALL", r"truncated card: the line 'XM1 YM1 ZM1' is missing"
    ),
    # issue 28, class 1: numbers Python cannot hold or that are not finite
    "20-digit node ID": (
        long_node_id, "/NODE", r"/NODE: field node_ID \(field 1\): '12345678901234567890' has "
        r"20 digits; Radioss's integers \(IDs, flags\) have at most 10",
    ),
    "length unit inf": (
        length_unit_inf, "/BEGIN", r"/BEGIN: length unit 'inf': 'inf' is not a finite number",
    ),
    # class 3: one element ID used twice (Radioss refuses it)
    "element ID twice": (
        brick_id_twice, "/BRICK",
        r"/BRICK/1: element ID 1 is used twice \(again at .*model_0000.rad:\d+, /BRICK/1\): "
        "an element ID names one element",
    ),
    # class 3: a flat brick (its top face on its bottom face), without a repeated node
    "flat brick": (
        flat_brick, "/BRICK", r"/BRICK/1: element 1 is flat or inside out: its volume at "
        r"node \d+ is not positive",
    ),
    "version 44": (
        version_44, "/BEGIN", r"input version 44: the block format of version 5.1 and later "
        r"\(Invers >= 51: fields of 10 and 20 characters\) is read",
    ),
    "version 90 without units lines": (
        version_90_units_by_cards, "/BEGIN", r"input version 90: no line of input units: the "
        r"units of decks before version 10 \(/UNIT/MASS, LENGTH, TIME\) are not read",
    ),
    "failure strain below 0": (
        failure_strain_negative, "/MAT/LAW2", r"EPS_p_max = -0.2: a failure plastic strain is > 0",
    ),
    "flow-stress cap below the yield stress": (
        cap_below_yield, "/MAT/LAW2", r"SIG_max0 = 0.3: the flow-stress cap must be above the "
        r"yield stress a = 0.4",
    ),
    "flow-stress cap after the rate factor": (
        cap_after_the_rate_factor, "/MAT/LAW2", r"ICC = 2: rwall_fem caps a \+ b eps_p\^n before",
    ),
}  # fmt: skip


def refused_in_one_line(path, card: str, pattern: str) -> None:
    """Loading the deck ``path`` is refused in one line naming the file and a line of the
    card whose header starts with ``card``, saying ``pattern``."""
    with pytest.raises(DeckError) as info:
        load_deck(path)
    message = str(info.value)
    assert "\n" not in message
    lines = path.read_text().splitlines()
    number = int(re.match(rf"{re.escape(str(path))}:(\d+): ", message)[1])
    header = max(i for i in range(number) if lines[i].startswith("/"))
    assert lines[header].startswith(card), message
    assert re.search(pattern, message), message


@pytest.mark.parametrize("case", list(CASES))
def test_bad_deck_is_one_line_naming_file_and_line(case, shared_dir):
    edit, card, pattern = CASES[case]
    refused_in_one_line(written(good(), shared_dir, edit), card, pattern)


def two_parts(*velocities) -> BarDeck:
    """The bar of good() in two bonded parts of one material: 2 (the bottom layer, "front")
    and 1 (the top one, "the_bar"), with an /INIVEL (velocity, part IDs) each."""
    d = BarDeck(units="kg-mm-ms", nz=2, front=1)
    d.part(pid=1)
    d.part(pid=2, title="front")
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    for k, (v, parts) in enumerate(velocities, start=1):
        d.group(k, "PART", parts)
        d.initial_velocity(v, k, iid=k)
    d.wall("PLANE", m1=(0, 0, 1), dsearch=1.0)
    return d


def split_part() -> BarDeck:
    d = BarDeck(units="kg-mm-ms", nz=2)
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    d.group(2, "NODE", d.face_nodes(0))
    d.initial_velocity((0, 0, -5.0), 2)
    d.wall("PLANE", m1=(0, 0, 1), dsearch=1.0)
    return d


INITIAL = {
    # name: (the deck, the card named, what the message says)
    "/INIVEL on some nodes of a part": (
        split_part, "/INIVEL/TRA/1",
        r"/INIVEL/TRA: group 2 holds 9 of the 27 nodes of /PART/1 \(the_bar; node 10 is not "
        r"in it\): an initial velocity is given to whole parts",
    ),
    "bonded parts at different velocities": (
        lambda: two_parts(((0, 0, -5.0), [1]), ((0, 0, -3.0), [2])), "/INIVEL/TRA/2",
        r"/PART/1 \(the_bar\) and /PART/2 \(front\) share 9 nodes \(node 10: they are "
        r"bonded\) but would start at \[0, 0, -5\] and \[0, 0, -3\] m/s: bonded parts start "
        "together",
    ),
    "a bonded part left at rest": (
        lambda: two_parts(((0, 0, -5.0), [1])), "/INIVEL/TRA/1",
        r"would start at \[0, 0, -5\] and \[0, 0, 0\] m/s",
    ),
    "a second velocity of a part": (
        lambda: two_parts(((0, 0, -5.0), [1, 2]), ((0, 0, -3.0), [1])), "/INIVEL/TRA/2",
        r"a second initial velocity of /PART/1 \(the_bar\): \[0, 0, -3\] m/s after "
        r"\[0, 0, -5\] m/s at .*model_0000.rad:\d+",
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", list(INITIAL))
def test_initial_velocity_not_of_whole_parts_is_one_line(case, shared_dir):
    """/INIVEL gives whole parts their velocity, and bonded parts start together: anything
    else is refused naming the /INIVEL card."""
    deck, card, pattern = INITIAL[case]
    refused_in_one_line(written(deck(), shared_dir), card, pattern)


class Lines(logging.Handler):
    def __init__(self, level=logging.WARNING):
        super().__init__(level)
        self.lines = []

    def emit(self, record):
        self.lines.append(record.getMessage())


def test_output_cards_are_skipped_with_one_notice_each(shared_dir):
    d = good()
    d.cards += ["/TH/RWALL/1", "wall", "FNX", "         1"]
    d.engine += ["/ANIM/VECT/VEL", "/PRINT/-100"]
    path = written(d, shared_dir)
    log, handler = logging.getLogger("rwall_fem"), Lines(logging.INFO)
    log.addHandler(handler)  # the command line's tests stop its propagation to pytest
    level = log.level  # and silence the ranks other than 0: every rank reads the deck here
    log.setLevel(logging.INFO)
    try:
        load_deck(path)
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
    skipped = [line for line in handler.lines if "skipped" in line]
    assert [s.split(": ")[3] for s in skipped] == ["/TH/RWALL/1", "/ANIM/VECT/VEL", "/PRINT/-100"]
    assert all(line.startswith("deck: notice: ") for line in skipped)


@pytest.mark.serial
def test_command_line_exits_2_with_one_line(tmp_path):
    path = written(good(), tmp_path, no_material)
    done = subprocess.run([sys.executable, "-m", "rwall_fem", "check", str(path)],
                          capture_output=True, text=True)  # fmt: skip
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "has no material" in done.stderr
    assert "Traceback" not in done.stderr


def engine_edit(value: str, card: str = "/RUN"):
    def edit(lines):
        lines[line_of(lines, card) + 1] = value

    return edit


ENGINE = {
    # issue 28, class 1: /RUN's Tstop not finite, with /ANIM/DT (frames over the run)
    "Tstop nan": (engine_edit("nan"), r"/RUN/model/1: field Tstop \(field 1\): 'nan' is not a "
                  "finite number"),
    "Tstop 1e999": (engine_edit("1e999"), r"field Tstop \(field 1\): '1e999' is not a finite"),
    "Tfreq inf": (engine_edit("0.0 inf", "/ANIM/DT"), r"/ANIM/DT: field Tfreq \(field 2\): "
                  "'inf' is not a finite number"),
}  # fmt: skip


@pytest.mark.parametrize("case", list(ENGINE))
def test_bad_engine_number_is_one_line_naming_the_engine_file(case, shared_dir):
    edit, pattern = ENGINE[case]
    d = good()
    d.engine += ["/ANIM/DT", "0.0 0.001"]
    path = written(d, shared_dir)
    engine = path.with_name("model_0001.rad")
    if MPI.COMM_WORLD.rank == 0:
        lines = engine.read_text().splitlines()
        edit(lines)
        engine.write_text("\n".join(lines) + "\n")
    MPI.COMM_WORLD.barrier()
    with pytest.raises(DeckError) as info:
        load_deck(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{engine}:")
    assert re.search(pattern, message), message


def test_odd_characters_are_read_as_radioss_reads_them(shared_dir):
    """Issue 28, class 2: no-break spaces in a /NODE line and a UTF-8 byte-order mark give
    the deck of plain spaces (one notice names the first no-break space)."""
    plain = written(good(), shared_dir)
    coordinates = read_deck(plain).coordinates
    odd = None
    if MPI.COMM_WORLD.rank == 0:
        lines = plain.read_text().splitlines()
        k = line_of(lines, "/NODE") + 2
        lines[k] = lines[k].replace("  ", "\u00a0\u00a0")
        odd = plain.with_name("odd_0000.rad")
        odd.write_bytes(codecs.BOM_UTF8 + "\n".join(lines).encode() + b"\n")
        plain.with_name("odd_0001.rad").write_text(plain.with_name("model_0001.rad").read_text())
    odd = MPI.COMM_WORLD.bcast(odd, root=0)
    deck = read_deck(odd)
    assert np.array_equal(deck.coordinates, coordinates)
    (notice,) = [n for n in deck.notices if "no-break" in n]
    assert re.match(rf"{re.escape(str(odd))}:\d+: a no-break space \(U\+00A0\) at column \d+ "
                    r"read as a space", notice)  # fmt: skip


@pytest.mark.serial
def test_a_warning_is_not_printed_before_the_error(tmp_path):
    """Issue 28, class 9: a deck whose property draws a warning and whose run cannot be
    built prints one line, the error; convert does not overwrite a scene without --force."""
    d = good()
    d.cards = [c.replace(f"{0.0:20g}" * 2 + f"{0.0:20g}", f"{0.1:20g}" * 2 + f"{0.0:20g}")
               for c in d.cards]  # qa, qb: a warning  # fmt: skip
    path = written(d, tmp_path)
    command = [sys.executable, "-m", "rwall_fem", "check", str(path), "--set", "run.max_steps=10"]
    done = subprocess.run(command, capture_output=True, text=True)
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "run.max_steps" in done.stderr, done.stderr
    done = subprocess.run(command[:-2], capture_output=True, text=True)
    assert done.returncode == 0 and "qa, qb (bulk viscosity) are not used" in done.stderr
    convert = [sys.executable, "-m", "rwall_fem", "convert", str(path), str(tmp_path / "scene")]
    assert subprocess.run(convert, capture_output=True).returncode == 0
    toml = tmp_path / "scene" / "model.toml"
    toml.write_text("# mine\n" + toml.read_text())
    again = subprocess.run(convert, capture_output=True, text=True)
    assert again.returncode == 2 and again.stderr.count("\n") == 1
    assert f"{toml}: exists; convert does not overwrite a scene" in again.stderr
    assert toml.read_text().startswith("# mine")
    forced = subprocess.run([*convert, "--force"], capture_output=True, text=True)
    assert forced.returncode == 0 and not toml.read_text().startswith("# mine")


def test_a_unit_id_of_no_unit_card_is_one_line(shared_dir):
    def edit(lines):
        k = line_of(lines, "/MAT/LAW1/1")
        lines[k] = "/MAT/LAW1/1/4"

    refused_in_one_line(written(good(), shared_dir, edit), "/MAT/LAW1/1/4",
                        r"/MAT/LAW1/1/4: unit_ID 4 refers to no /UNIT")  # fmt: skip


def test_a_deck_of_version_9_with_units_lines_reads(shared_dir):
    def edit(lines):
        lines[line_of(lines, "/BEGIN") + 2] = f"{90:10d}{0:10d}"

    assert read_deck(written(good(), shared_dir, edit)).version == 90


def test_bcs_and_impvel_along_one_axis_of_a_main_node_is_one_line(shared_dir):
    """A /BCS holds a main node's component at VX0..VZ0 (motion.held), an /IMPVEL
    prescribes it: both along Z are refused in one line naming the /RWALL."""
    d = good()
    d.extra_nodes.append((901, (0.0, 0.0, 0.003)))
    d.group(5, "NODE", [901])
    d.function(7, [(0, 1), (10, 1)])
    d.imposed_velocity(1, 7, "Z", 5, 1e-5, -2.0)
    d.clamp(3, "   001 000", 5)
    d.wall("PLANE", 2, node=901, m1=(0.0, 0.0, 1.0), dsearch=1.0)
    refused_in_one_line(written(d, shared_dir), "/RWALL",
                        r"/RWALL/PLANE/2: its node has both a /BCS and an /IMPVEL along Z: give "
                        r"one")  # fmt: skip
