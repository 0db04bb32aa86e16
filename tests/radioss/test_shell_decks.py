"""Radioss decks of shells: /SHELL, /SH3N, /PROP/SHELL (/PROP/TYPE1), /BCS rotation codes.

A plate of shells given as a deck (in kg-mm-ms) runs as the scene a user would write for
it (the built-in plate's mid-surface, in SI): the same impulse, energies and rebound to
round-off. The peer deck of a clamped steel plate struck by a sphere wall
(``../shared/peer-decks/gen_shell.py``) gives OpenRadioss's answers within the
tolerances its README suggests, at 5 mm (1,600 shells) against OpenRadioss's at 2.5 mm.
Bad shell cards are refused in one line naming the file and line.
"""

import copy
import math
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.build import run_in_folder
from rwall_fem.radioss import DeckError, load_deck

from .decks import UNITS, BarDeck, f20, i10

DECKS = Path(__file__).resolve().parents[3] / "shared" / "peer-decks"
comm = MPI.COMM_WORLD


class PlateDeck(BarDeck):
    """A plate of nx x ny /SHELL quadrilaterals of side h at z = z0 (SI values), in units."""

    def write(self, directory: Path, name: str = "model", one_file: str = "") -> Path:
        _, names = UNITS[self.units]
        lines = ["#RADIOSS STARTER", "/BEGIN", name, "      2026"]
        lines += ["".join(n.rjust(20) for n in names)] * 2 + ["/NODE"]
        for j in range(self.ny + 1):
            for i in range(self.nx + 1):
                x = (i * self.h, j * self.h, self.z0)
                lines.append(i10(self.node_id(i, j, 0))
                             + "".join(f20(self.q(c, "length")) for c in x))  # fmt: skip
        lines.append("/SHELL/1")
        e = 0
        for j in range(self.ny):
            for i in range(self.nx):
                e += 1
                n = self.node_id
                ids = [n(i, j, 0), n(i + 1, j, 0), n(i + 1, j + 1, 0), n(i, j + 1, 0)]
                lines.append(i10(e) + "".join(i10(q) for q in ids))
        lines += self.cards + ["/END"]
        engine = ["#RADIOSS ENGINE", f"/RUN/{name}/1", f"{self.q(self.end_time, 'time'):.14g}"]
        (Path(directory) / f"{name}_0001.rad").write_text("\n".join(engine + self.engine
                                                                     + ["/END"]) + "\n")  # fmt: skip
        starter = Path(directory) / f"{name}_0000.rad"
        starter.write_text("\n".join(lines) + "\n")
        return starter

    def shell(self, thick: float, ishell: int = 1, n: int = 5, pid: int = 1) -> None:
        self.cards += [f"/PROP/SHELL/{pid}", "shell",
                       i10(ishell) + i10(0) + i10(0) + i10(0) + i10(0) + " " * 10 + f20(0.0),
                       f20(0.0) * 5,
                       i10(n) + i10(0) + f20(self.q(thick, "length")) + f20(0.0) + " " * 10
                       + i10(2) + i10(1)]  # fmt: skip


def plate_deck(units="kg-mm-ms") -> PlateDeck:
    """A 40 x 20 mm steel plate of 8 x 4 shells, 1 mm, at 5 m/s onto a plane 0.1 mm below."""
    d = PlateDeck(units=units, h=5e-3, nx=8, ny=4, nz=0, z0=1e-4, end_time=6e-5)
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.shell(1e-3, ishell=1)
    d.group(1, "PART", [1])
    d.initial_velocity((0.0, 0.0, -5.0), 1)
    d.wall("PLANE", m1=(0.0, 0.0, 1.0), dsearch=1.0)
    return d


def written(d, directory, edit=None) -> Path:
    path = None
    if comm.rank == 0:
        path = d.write(directory)
        if edit:
            lines = path.read_text().splitlines()
            edit(lines)
            path.write_text("\n".join(lines) + "\n")
    return comm.bcast(path, root=0)


def test_a_shell_deck_runs_as_its_scene(shared_dir):
    deck = load_deck(written(plate_deck(), shared_dir))
    assert deck.element.thickness == pytest.approx(1e-3, rel=1e-15)
    assert deck.element.formulation == "bwc" and deck.element.points == 5
    hk = 3 * 0.5 * 0.01 * (1 - 0.3**2)  # Radioss's CHVIS3 elastic hourglass forces
    raw = {
        "run": {"end_time": 6e-5},
        "mesh": {"shape": "plate", "origin": [0, 0, 1e-4 - 5e-4], "size": [0.04, 0.02, 1e-3],
                 "element_size": 5e-3, "cell": "quadrilateral"},
        "material": {"model": "linear_elastic", "density": 7850.0, "young": 210e9,
                     "poisson": 0.3},
        "element": {"thickness": 1e-3, "formulation": "bwc", "points": 5,
                    "hourglass_stiffness": hk},
        "initial": {"velocity": [0.0, 0.0, -5.0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 0, "plot": False},
    }  # fmt: skip
    by_hand = build_simulation(parse_scene(copy.deepcopy(raw), source="t"), comm,
                               shared_dir / "scene")  # fmt: skip
    by_hand.run()
    from_deck = build_simulation(deck, comm, shared_dir / "deck")
    from_deck.run()
    a, b = by_hand.history.summary, from_deck.history.summary
    assert a["steps"] == b["steps"]
    assert b["walls"][0]["impulse"][2] < 0.0  # the plate pushes the wall against its normal
    assert b["walls"][0]["impulse"][2] == pytest.approx(a["walls"][0]["impulse"][2], rel=1e-9)
    for name in ("kinetic", "rotational_kinetic", "internal", "wall_work"):
        assert b["energy"][name] == pytest.approx(a["energy"][name], rel=1e-9, abs=1e-15)
    assert b["energy"]["max_balance_error"] <= 1e-12


def test_bcs_rotation_codes_hold_the_shells_rotations(shared_dir):
    d = plate_deck()
    d.group(2, "NODE", [d.node_id(0, j, 0) for j in range(d.ny + 1)])
    d.clamp(1, "111 111", 2)
    scene = load_deck(written(d, shared_dir))
    (boundary,) = scene.boundaries
    assert (boundary.components, boundary.rotations) == ("xyz", "xyz")


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda lines: _replace(lines, "/PROP/SHELL/1", 2, i10(7)), "Ishell = 7: supported: 1, 2"),
        (lambda lines: _replace(lines, "/PROP/SHELL/1", 4, i10(5) + i10(0) + f20(0.0)),
         "Thick = 0 m: a shell needs a thickness > 0"),
        (lambda lines: _replace(lines, "/PROP/SHELL/1", 4, i10(11)), "N = 11: 1 to 10 points"),
        (lambda lines: _replace(lines, "/PROP/SHELL/1", 4, i10(5) + i10(0) + f20(1.0)
                                + f20(0.0) + " " * 10 + i10(3)), "Ithick = 3: 1 "),
        (lambda lines: _replace(lines, "/PROP/SHELL/1", 2, i10(1) + i10(0) * 4 + " " * 10
                                + f20(1.5)), "P_thickfail = 1.5: a share"),
        (lambda lines: _replace(lines, "/SHELL/1", 1, i10(1) + i10(1) * 2 + i10(10) + i10(11)),
         "element 1 repeats a node"),
    ],
    ids=["ishell", "thickness", "points", "ithick", "thickfail", "degenerate"],
)
def test_bad_shell_cards_are_one_line(edit, message, shared_dir):
    path = written(plate_deck(), shared_dir, edit)
    with pytest.raises(DeckError, match=message) as caught:
        load_deck(path)
    assert "\n" not in str(caught.value) and "model_0000.rad:" in str(caught.value)


def test_ithick_and_p_thickfail_map_onto_the_element(shared_dir):
    """Ithick = 1: the thickness follows the membrane strain; P_thickfail: the share of the
    points through the thickness that fail a cell."""

    def edit(lines):
        _replace(lines, "/PROP/SHELL/1", 2, i10(1) + i10(0) * 4 + " " * 10 + f20(0.6))
        _replace(lines, "/PROP/SHELL/1", 4, i10(5) + i10(0) + f20(1.0) + f20(0.0) + " " * 10
                 + i10(1))  # fmt: skip

    scene = load_deck(written(plate_deck(), shared_dir, edit))
    assert scene.element.thickness_change is True
    assert scene.element.failed_share == pytest.approx(0.6, rel=1e-15)
    assert load_deck(written(plate_deck(), shared_dir)).element.thickness_change is None


def test_ishell_1_hourglass_stiffness_stores_radioss_elastic_hourglass_energy():
    """Ishell 1's hourglass forces in OpenRadioss are elastic (CHVIS3, engine/source/
    elements/shell/coque/chvis3.F): per step HOUR += (HELAS hm E t / 4) dt hg with
    hg = sum GAMA_I v_I (GAMA = +-1 on a parallelogram, HELAS = 0.5, radioss2.F), force
    HOUR GAMA_I on node I, power HOUR hg. A square cell driven slowly through the in-plane
    hourglass mode u_I = G_I d: the kernel with the deck's hk = 3 HELAS hm (1 - nu^2) (and
    no viscosity) stores the energy 1/2 K hg^2 of that update, to 1e-9, and its nodes
    carry its forces HOUR GAMA_I (to 1e-3: the cell's shape changes by d / a)."""
    from rwall_fem.radioss.cards.shells import HELAS
    from rwall_fem.shells.elements import ShellKernel, ShellTechnology

    E, nu, t, a, hm = 210e9, 0.3, 1.5e-3, 2.5e-3, 0.01
    material = SimpleNamespace(model="linear_elastic", plastic=False, young=E, poisson=nu,
                               density=7850.0)  # fmt: skip
    hk = 3 * HELAS * hm * (1 - nu**2)
    technology = ShellTechnology.choose("quadrilateral", "bwc", hourglass=(0.0, 0.0, 0.0),
                                        hourglass_stiffness=hk)  # fmt: skip
    X = np.array([[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, a, 0.0], [0.0, a, 0.0]])
    kernel = ShellKernel(material, technology, np.array([[0, 1, 2, 3]], np.int32), t)
    G = np.array([1.0, -1.0, 1.0, -1.0])
    d, steps, dt = 1e-7, 200, 1e-7
    energy, hour, reference = np.zeros(4), 0.0, 0.0
    rate = np.zeros_like(X)
    rate[:, 0] = G * d / (steps * dt)
    for n in range(1, steps + 1):
        f, m = np.zeros_like(X), np.zeros_like(X)
        kernel.run(dt, X, rate * n * dt, rate, np.zeros_like(X), f, m, energy=energy)
        hg = G @ rate[:, 0]
        hour += HELAS * hm * E * t / 4 * dt * hg
        reference += dt * hour * hg
    exact = 2 * HELAS * hm * E * t * d**2  # 1/2 K hg^2, which that sum reaches as dt -> 0
    assert reference == pytest.approx(exact, rel=1.0 / steps)
    assert energy[1] == pytest.approx(exact, rel=1e-9)
    # the forces HOUR GAMA_I, to the cell's change of shape (d / a = 4e-5: gamma at x)
    np.testing.assert_allclose(np.abs(f[:, 0]), hour, rtol=1e-3)
    assert np.abs(f[:, 1:]).max() <= 1e-3 * hour


def test_blank_ishell_and_iplas_take_openradioss_defaults(shared_dir):
    """A blank Ishell is 1 (Belytschko-Tsay: OpenRadioss's starter, defaults_mod.F90
    init_def_elem, gives /DEF_SHELL's Ishell 1 outside /IMPLICIT; hm_read_prop01.F takes
    it for a blank field); a blank Iplas is Radioss's radial return for LAW2 (cgrtails.F
    keeps 0, m2cplr.F scales the trial stress), read as the exact return with one warning;
    Iplas 1 gives none."""

    def blank(lines):
        _replace(lines, "/PROP/SHELL/1", 2, " " * 10)
        k = lines.index("/PROP/SHELL/1") + 4
        lines[k] = lines[k][:80]

    said = []
    scene = load_deck(written(plate_deck(), shared_dir, blank), report=said)
    assert scene.element.formulation == "bwc"
    assert any("Ishell = 1: read as" in w for w in said[0].warnings)
    warned = [w for w in said[0].warnings if "Iplas = 0 (blank)" in w]
    assert len(warned) == 1 and "exact one of Iplas 1" in warned[0]
    said = []
    load_deck(written(plate_deck(), shared_dir), report=said)
    assert not [w for w in said[0].warnings if "Iplas" in w]


@pytest.mark.parametrize("ishell, idrill", [(1, 1), (3, 0), (3, 2)])
def test_idrill_and_ishell_3_map_onto_the_quadrilaterals_kernel(ishell, idrill, shared_dir):
    """Idrill 1: drilling springs of 0.01 G t A per node (2 or blank: none); Ishell 3 (the
    elasto-plastic hourglass stiffness): the warping-corrected element with the elastic
    hourglass stiffness 0.5. The values reach the compiled kernel of the deck's body."""

    def edit(lines):
        _replace(lines, "/PROP/SHELL/1", 2, i10(ishell) + i10(0) * 2 + i10(idrill) + i10(0))

    scene = load_deck(written(plate_deck(), shared_dir, edit))
    drilling = 0.01 if idrill == 1 else None
    hourglass = 0.5 if ishell == 3 else pytest.approx(3 * 0.5 * 0.01 * (1 - 0.3**2), rel=1e-15)
    assert (scene.element.drilling_stiffness, scene.element.hourglass_stiffness) == (
        drilling, hourglass)  # fmt: skip
    assert scene.element.formulation == "bwc"
    sim = build_simulation(scene, comm, shared_dir)
    compiled = sim.internal.elements[0].kernel.shell
    assert (compiled.kd, compiled.hk) == (drilling or 0.0, scene.element.hourglass_stiffness)


@pytest.mark.parametrize("ishell", [1, 24])
def test_ishell_24_takes_qeph_step_length(ishell, shared_dir):
    """Ishell 24 (QEPH): formulation "qeph" with its hourglass yield (no hm, hf, hr) and
    QEPH's characteristic length of the step, with dn = 0.015 (the compiled kernel's); Ishell 1: Radioss's Belytschko-Tsay length. The body's first
    step is 0.9 of its smallest cell's L_c / sqrt(E / rho) by the rule."""

    def edit(lines):
        _replace(lines, "/PROP/SHELL/1", 2, i10(ishell) + i10(0) * 4)

    scene = load_deck(written(plate_deck(), shared_dir, edit))
    qeph = ishell == 24
    assert scene.element.step_length == ("qeph" if qeph else None)
    # Ishell 24: QEPH's own hourglass forces with their yield; hm, hf, hr not read
    assert scene.element.formulation == ("qeph" if qeph else "bwc")
    assert bool(scene.element.hourglass_yield) == qeph
    sim = build_simulation(scene, comm, shared_dir)
    elements = sim.internal.elements[0]
    compiled = elements.kernel.shell
    assert (compiled.qeph_step, compiled.qeph_dn) == (int(qeph), 0.015)
    assert (compiled.qeph_physical, compiled.qeph_hourglass) == (int(qeph), int(qeph))
    assert (compiled.hm, compiled.hk) == ((0.0, 0.0) if qeph else (0.01, compiled.hk))
    side = comm.allreduce(elements.length0.min() if len(elements.length0) else np.inf, op=MPI.MIN)
    square = 1 / math.sqrt(2 * (0.78 + 0.22 * (3.413 * 0.2929) ** 3) * 1.25 / 2)
    factor = square * (math.sqrt(1 + 0.015**2) - 0.015) if qeph else 1.0
    assert side == pytest.approx(factor * 5e-3, rel=1e-9)  # the deck's 5 mm squares

    def other_dn(lines):
        edit(lines)
        _replace(lines, "/PROP/SHELL/1", 3, f20(0.0) * 4 + f20(0.02))

    said = []
    load_deck(written(plate_deck(), shared_dir, other_dn), report=said)
    warned = [w for w in said[0].warnings if "dn = 0.02" in w]
    assert len(warned) == int(qeph) and all("take dn = 0.015" in w for w in warned)


def test_idrill_other_than_1_and_2_is_refused(shared_dir):
    def edit(lines):
        _replace(lines, "/PROP/SHELL/1", 2, i10(1) + i10(0) * 2 + i10(3) + i10(0))

    with pytest.raises(DeckError, match="Idrill = 3: 1 .drilling springs. or 2") as caught:
        load_deck(written(plate_deck(), shared_dir, edit))
    assert "\n" not in str(caught.value) and "model_0000.rad:" in str(caught.value)


def test_a_solid_property_on_shells_and_shells_beside_solids_are_refused(shared_dir):
    d = plate_deck()
    d.cards = [c.replace("/PROP/SHELL/1", "/PROP/SHELL/2") for c in d.cards]
    d.solid(24, pid=1)
    with pytest.raises(DeckError, match="property 1 is not a property of /SHELL, /SH3N"):
        load_deck(written(d, shared_dir))
    bar = BarDeck(units="kg-mm-ms", nz=2)
    bar.part()
    bar.elastic(7850.0, 210e9, 0.3)
    bar.solid(24)
    bar.cards += ["/SHELL/1", i10(99) + i10(1) + i10(2) + i10(5) + i10(4)]
    with pytest.raises(DeckError, match="a scene mixes no shells and solids in one mesh"):
        load_deck(written(bar, shared_dir))


def _replace(lines, card, offset, text):
    k = lines.index(card) + offset
    lines[k] = text + lines[k][len(text):]


@pytest.mark.serial
@pytest.mark.skipif(not (DECKS / "gen_shell.py").is_file(), reason="no ../shared/peer-decks")
def test_the_clamped_plate_deck_gives_openradioss_answers(tmp_path):
    """The plate 200 x 200 x 2 mm, rim clamped (/BCS 111 111), struck at 20 m/s by a 1 kg
    sphere wall, at 5 mm; OpenRadioss at 2.5 mm (Ishell 24): travel 17.95 mm, rebound
    +4.85 m/s, impulse 24.92 N s, peak force 24.8 kN (10 us mean), plastic work 186.9 J."""
    subprocess.run([sys.executable, str(DECKS / "gen_shell.py"), "plate", "--h", "5",
                    "--name", "plate", "--out", str(tmp_path)], check=True,
                   capture_output=True)  # fmt: skip
    sim = build_simulation(load_deck(tmp_path / "plate_0000.rad"), out=tmp_path / "out")
    run_in_folder(sim)
    s = sim.history.summary
    walls = sim.history.wall(0)
    from conftest import COLUMN

    t, z, f = (walls[:, COLUMN[c]] for c in ("time", "position_z", "force_z"))
    window = max(1, round(1e-5 / np.diff(t).mean()))
    mean = np.convolve(f, np.ones(window) / window, mode="same")
    assert (z[0] - z.min()) * 1e3 == pytest.approx(17.95, rel=0.03)
    assert s["walls"][0]["velocity"][2] == pytest.approx(4.85, rel=0.05)
    assert s["walls"][0]["impulse"][2] == pytest.approx(24.92, rel=0.01)
    assert np.abs(mean).max() / 1e3 == pytest.approx(24.8, rel=0.05)
    assert s["plastic_work"] == pytest.approx(186.9, rel=0.05)
    assert s["energy"]["max_balance_error"] <= 1e-6
