"""Deck files read as Radioss reads them: included files that start with a free-text
header or with lines continuing the including card, text before the first card,
#enddata, one-file decks (engine first, as Radioss's single-file input, or after the
starter), //SUBMODEL without offsets, numbers with D or no exponent letter, tabs, CRLF,
byte-order marks, Latin-1 and UTF-16 files, no-break spaces; a number that is not finite
or an integer of more than 10 digits is refused naming the field."""

import codecs

import numpy as np
import pytest

from rwall_fem.radioss.deck_files import read_cards, read_deck_text
from rwall_fem.radioss.reader import Card, DeckError, Line, NumberError, fixed_table, parse_number

HEADER = [f"Copyright>        line {k} of a licence notice" for k in range(1, 24)]
NODES = [f"{k:10d}{k * 0.5:20.6g}{0.0:20g}{1.0:20g}" for k in range(1, 5)]


@pytest.mark.parametrize(
    ("text", "integer", "value"),
    [("2.1D5", False, 2.1e5), ("2.1d+5", False, 2.1e5), ("7.8-9", False, 7.8e-9),
     ("1.5+3", False, 1.5e3), ("-2.-3", False, -2e-3), ("  .5E1 ", False, 5.0), ("", False, 0.0),
     ("1.", True, 1), ("1.0D0", True, 1), ("-7", True, -7), ("0000000012", True, 12),
     ("9999999999", True, 9999999999)],
)  # fmt: skip
def test_numbers_as_radioss_reads_them(text, integer, value):
    got = parse_number(text, integer=integer)
    assert got == value and isinstance(got, int) == integer


@pytest.mark.parametrize(
    ("text", "integer", "why"),
    [("nan", False, "'nan' is not a finite number"), ("inf", False, "not a finite number"),
     ("1e999", False, "'1e999' is not a finite number"), ("-1D400", False, "not a finite"),
     ("1.5", True, "'1.5' is not an integer"),
     ("12345678901234567890", True, "has 20 digits; Radioss's integers .* at most 10"),
     ("1e15", True, "has 16 digits"), ("1" * 5000, True, "has 5000 digits"),
     ("2.1.0e2", False, "cannot read '2.1.0e2' as a number"),
     ("1.0\u00d7", False, r"the character '×', U\+00D7, at its character 4")],
)  # fmt: skip
def test_numbers_that_are_not_refused_naming_why(text, integer, why):
    with pytest.raises(NumberError, match=why):
        parse_number(text, integer=integer)


def nodes_of(card: Card) -> tuple[np.ndarray, np.ndarray]:
    i, x, y, z = fixed_table(card, 0, "i:id f:x f:y f:z")
    return i, np.column_stack([x, y, z])


def test_an_included_file_may_start_with_a_free_text_header(tmp_path):
    """A copyright-style header of 23 lines heading an included file is skipped with one
    notice; the cards after it are read."""
    (tmp_path / "model.inc").write_text("\n".join(HEADER + ["/NODE", *NODES]) + "\n")
    (tmp_path / "a_0000.rad").write_text("#RADIOSS STARTER\n/BEGIN\nname\n#include model.inc\n")
    text = read_deck_text(tmp_path / "a_0000.rad")
    assert [c.name for c in text.starter] == ["/BEGIN", "/NODE"]
    ids, x = nodes_of(text.starter[1])
    assert ids.tolist() == [1, 2, 3, 4] and x[3].tolist() == [2.0, 0.0, 1.0]
    (notice,) = text.notices
    assert notice.startswith(f"{tmp_path / 'model.inc'}:1-23: 23 lines of text outside any card")


def test_an_included_file_may_continue_the_including_card(tmp_path):
    """Lines before an included file's first card continue the card that includes it, as
    if pasted in place; a header after the deck's last card is skipped too (Radioss's QA
    decks end so)."""
    (tmp_path / "nodes.inc").write_text("\n".join([*NODES[2:], "/NODE", "  9,1.0,2.0,3.0"]) + "\n")
    (tmp_path / "legal.inc").write_text("\n".join(HEADER) + "\n")
    (tmp_path / "a_0000.rad").write_text(
        "\n".join(
            [
                "/BEGIN",
                "name",
                "/NODE",
                *NODES[:2],
                "#include nodes.inc",
                "#include legal.inc",
                "/END",
            ]
        )
        + "\n"  # fmt: skip
    )
    cards = read_cards(tmp_path / "a_0000.rad")
    assert [c.name for c in cards] == ["/BEGIN", "/NODE", "/NODE"]
    assert nodes_of(cards[1])[0].tolist() == [1, 2, 3, 4]
    assert cards[1].lines[2].where == f"{tmp_path / 'nodes.inc'}:1"
    assert nodes_of(cards[2])[1].tolist() == [[1.0, 2.0, 3.0]]


def test_text_before_the_first_card_and_after_enddata(tmp_path):
    (tmp_path / "b.inc").write_text("/TITLE\nkept\n#enddata\n/NODE\n1 2 3 4\n")
    (tmp_path / "a_0000.rad").write_text(
        "A deck written by hand\nfor a test\n/BEGIN\nname\n#include b.inc\n/END\n"
    )
    text = read_deck_text(tmp_path / "a_0000.rad")
    assert [c.name for c in text.starter] == ["/BEGIN", "/TITLE"]
    assert "a_0000.rad:1-2: 2 lines of text outside any card" in text.notices[0]


def test_line_ends_tabs_marks_and_encodings(tmp_path):
    """CRLF and CR line ends, a UTF-8 byte-order mark, tab-separated fields, a Latin-1
    title, a UTF-16 file: the same cards and numbers."""
    lines = ["#RADIOSS STARTER", "/BEGIN", "Stahlträger", "/NODE", *NODES[:2],
             "\t3\t1.0D0\t0.0\t1.0", "4,2.0,0.0,1.0"]  # fmt: skip
    variants = {
        "utf8-bom-crlf": codecs.BOM_UTF8 + "\r\n".join(lines).encode(),
        "cr": "\r".join(lines).encode(),
        "latin1": "\n".join(lines).encode("latin-1"),
        "utf16": "\n".join(lines).encode("utf-16"),
    }
    for name, data in variants.items():
        (tmp_path / f"{name}_0000.rad").write_bytes(data)
        cards = read_cards(tmp_path / f"{name}_0000.rad")
        assert [c.name for c in cards] == ["/BEGIN", "/NODE"], name
        assert cards[0].title() == "Stahlträger", name
        ids, x = nodes_of(cards[1])
        assert ids.tolist() == [1, 2, 3, 4], name
        assert x[2].tolist() == [1.0, 0.0, 1.0] and x[3].tolist() == [2.0, 0.0, 1.0], name


def test_no_break_spaces_are_spaces_with_one_notice(tmp_path):
    nbsp = NODES[1].replace(" ", "\u00a0", 12)
    (tmp_path / "a_0000.rad").write_text("\n".join(["/BEGIN", "n", "/NODE", NODES[0], nbsp]))
    text = read_deck_text(tmp_path / "a_0000.rad")
    assert nodes_of(text.starter[1])[0].tolist() == [1, 2]
    (notice,) = text.notices
    where = f"{tmp_path / 'a_0000.rad'}:5"
    assert notice == f"{where}: a no-break space (U+00A0) at column 1 read as a space"


def test_one_file_decks_split_into_starter_and_engine(tmp_path):
    starter = ["/BEGIN", "name", "/NODE", *NODES[:1], "/END"]
    engine = ["/RUN/name/1", "2.0", "/ANIM/DT", "0 1"]
    forms = {"engine_first": ["#RADIOSS", *engine, "/END/ENGINE", *starter],
             "starter_first": [*starter, *engine, "/END/ENGINE"],
             "no_end": [*engine, "/END/ENGINE", *starter[:-1]]}  # fmt: skip
    for name, lines in forms.items():
        (tmp_path / f"{name}_0000.rad").write_text("\n".join(lines) + "\n")
        text = read_deck_text(tmp_path / f"{name}_0000.rad")
        assert [c.name for c in text.starter] == ["/BEGIN", "/NODE"], name
        assert [c.name for c in text.engine] == ["/RUN/name/1", "/ANIM/DT"], name
        assert text.engine_block, name
    (tmp_path / "two_0000.rad").write_text("\n".join(starter + ["/RUN/x/1", "1.0"]) + "\n")
    text = read_deck_text(tmp_path / "two_0000.rad")
    assert not text.engine and "1 cards after /END not read" in text.notices[0]


def test_submodels_without_offsets_are_read_in_place(tmp_path):
    lines = ["/BEGIN", "name", "//SUBMODEL/1", "a submodel", "", "/NODE", *NODES[:1], "//ENDSUB"]
    (tmp_path / "a_0000.rad").write_text("\n".join(lines) + "\n")
    text = read_deck_text(tmp_path / "a_0000.rad")
    assert [c.name for c in text.starter] == ["/BEGIN", "/NODE"]
    assert "//SUBMODEL/1: read in place" in text.notices[0]
    lines[4] = "         0      1000"
    (tmp_path / "a_0000.rad").write_text("\n".join(lines) + "\n")
    with pytest.raises(DeckError, match=r"a_0000.rad:5: //SUBMODEL/1: ID offsets \(0 1000\)"):
        read_deck_text(tmp_path / "a_0000.rad")


def test_free_format_and_tabs_in_a_line():
    assert Line("1, 2.0,,4", "f", 1).words() == ["1", "2.0", "", "4"]
    assert Line("1\t2.0  4", "f", 1).words() == ["1", "2.0", "4"]
    assert Line("1\t2.0", "f", 1).free and not Line("         1       2.0", "f", 1).free
