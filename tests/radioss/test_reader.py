"""The block format: fixed and free fields, comments, #include, units by hand, speed."""


import numpy as np
import pytest

from rwall_fem.radioss.deck_files import read_cards
from rwall_fem.radioss.reader import DeckError, fixed_table
from rwall_fem.radioss.units import UnitSystem, parse_unit


@pytest.mark.parametrize(
    ("text", "quantity", "size"),
    [("kg", "mass", 1.0), ("Mg", "mass", 1e3), ("g", "mass", 1e-3), ("mm", "length", 1e-3),
     ("m", "length", 1.0), ("ms", "time", 1e-3), ("s", "time", 1.0), ("mus", "time", 1e-6),
     ("1000", "mass", 1e3), ("in", "length", 0.0254), ("xx", "length", None)],
)  # fmt: skip
def test_units_by_hand(text, quantity, size):
    assert parse_unit(text, quantity) == (pytest.approx(size) if size else None)


def test_derived_units_by_hand():
    kg_mm_ms = UnitSystem(1.0, 1e-3, 1e-3)
    assert kg_mm_ms.factor("stress") == pytest.approx(1e9)  # GPa
    assert kg_mm_ms.factor("density") == pytest.approx(1e9)  # kg/mm^3
    assert kg_mm_ms.factor("velocity") == pytest.approx(1.0)  # m/s
    mg_mm_s = UnitSystem(1e3, 1e-3, 1.0)
    assert mg_mm_s.factor("stress") == pytest.approx(1e6)  # MPa
    assert mg_mm_s.factor("density") == pytest.approx(1e12)  # t/mm^3
    assert UnitSystem(1e-3, 1e-3, 1e-3).factor("stress") == pytest.approx(1e6)  # g-mm-ms: MPa


def test_comments_include_free_format(tmp_path):
    (tmp_path / "nodes.inc").write_text("$ included\n/NODE\n  1, 1.5, 2.0D0, -3\n")
    (tmp_path / "a.rad").write_text(
        "# comment\n/BEGIN\nname\n#include nodes.inc\n/NODE\n"
        "         2                 1.0                 2.0                 3.0\n/END\nignored\n"
    )
    cards = read_cards(tmp_path / "a.rad")
    assert [c.name for c in cards] == ["/BEGIN", "/NODE", "/NODE"]
    ids, x, y, z = fixed_table(cards[1], 0, "i:id f:x f:y f:z")
    assert (ids[0], x[0], y[0], z[0]) == (1, 1.5, 2.0, -3.0)
    assert cards[1].lines[0].where.endswith("nodes.inc:3")
    ids, x, y, z = fixed_table(cards[2], 0, "i:id f:x f:y f:z")
    assert (ids[0], z[0]) == (2, 3.0)


def test_include_of_itself_is_refused(tmp_path):
    (tmp_path / "a.rad").write_text("/BEGIN\n#include a.rad\n")
    with pytest.raises(DeckError, match=r"a.rad:2: #include a.rad: includes itself"):
        read_cards(tmp_path / "a.rad")


def test_a_large_node_block_reads_every_node_exactly(tmp_path):
    """200,000 nodes (a block read as a whole array, not line by line): every ID and
    coordinate back to the 12 digits written. Its speed is not tested (about 1 s)."""
    n = 200_000
    ids = np.arange(1, n + 1)
    xyz = np.random.default_rng(1).random((n, 3)) * 100
    with open(tmp_path / "big.rad", "w") as f:
        f.write("/NODE\n")
        np.savetxt(f, np.column_stack([ids, xyz]), fmt=["%10d", "%20.12g", "%20.12g", "%20.12g"],
                   delimiter="")  # fmt: skip
    (card,) = read_cards(tmp_path / "big.rad")
    i, x, y, z = fixed_table(card, 0, "i:id f:x f:y f:z")
    assert np.array_equal(i, ids) and np.allclose(np.column_stack([x, y, z]), xyz, rtol=1e-11)
