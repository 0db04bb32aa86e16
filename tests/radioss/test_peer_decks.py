"""The peer decks of ../shared/peer-decks run unchanged through the deck reader and give
OpenRadioss's answers (its README): here the bar on a plane, coarse (2 mm hexahedra, 1,250
cells) against OpenRadioss's answers at 1 mm: the wall impulse, the end of contact and the
rebound within 0.5 %. The full comparison (the bar at 1 mm, the Taylor rod):
``bench/peer_decks.py``."""

import subprocess
import sys
from pathlib import Path

import pytest

from rwall_fem.build import build_simulation, run_in_folder
from rwall_fem.radioss import load_deck

DECKS = Path(__file__).resolve().parents[3] / "shared" / "peer-decks"


@pytest.mark.serial
@pytest.mark.skipif(not (DECKS / "gen_bar.py").is_file(), reason="no ../shared/peer-decks")
def test_bar_deck_gives_openradioss_answers(tmp_path):
    subprocess.run([sys.executable, str(DECKS / "gen_bar.py"), "--h", "2.0", "--name", "bar",
                    "--out", str(tmp_path)], check=True, capture_output=True)  # fmt: skip
    sim = build_simulation(load_deck(tmp_path / "bar_0000.rad"), out=tmp_path / "out")
    run_in_folder(sim)
    s = sim.history.summary
    wall = s["walls"][0]
    assert -wall["impulse"][2] == pytest.approx(1.5386, rel=5e-3)  # N s
    assert wall["last_contact"] == pytest.approx(39.14e-6, rel=5e-3)  # s
    assert s["final_momentum"][2] / s["mass"] == pytest.approx(9.600, rel=5e-3)  # m/s
