"""What Radioss's starter warns about, rwall_fem warns about too (stderr, summary.json,
run.log), and the run goes on as the spec says:

- secondary nodes that start behind a wall (the bar's axis flipped, or normal_point on
  the wrong side): before, 329 nodes were held at t = 0 without a word;
- a wall whose secondary set is empty (refused when the scene's own exclusions emptied
  it: ``bad_scenes/74_*``);
- nodes both prescribed by a [[boundary]] and secondary to a wall: the boundary
  condition wins on its components (it acts after the walls).

The bar has one hexahedron across and N = 10 along z: 4 (N + 1) nodes, all on the
boundary, 4 on each end face.
"""

import json

import pytest
from conftest import bar_scene, run
from mpi4py import MPI

from rwall_fem.cli import main

N, H = 10, 1e-3
L = N * H


def test_nodes_starting_behind_a_wall_are_reported_and_kept(shared_dir, tmp_path, capsys):
    raw = bar_scene(elements=N, h=H)
    raw["wall"][0]["normal_point"] = [0.0, 0.0, -1.0]  # the free side below: the bar is behind
    sim = run(raw, shared_dir)
    wall = sim.history.summary["walls"][0]
    # Every node but the 4 of the lower face (on the plane) is behind it; the top face
    # is deepest, at L.
    assert wall["initially_penetrated"] == 4 * N
    assert wall["deepest_penetration"] == pytest.approx(L, rel=1e-12)
    assert sim.status == "done"
    [warning] = sim.history.summary["warnings"]
    assert warning.startswith(f"wall[0]: {4 * N} secondary nodes start behind the wall, the ")
    assert "deepest 0.01 m at (" in warning and "keeps them there" in warning

    scene = shared_dir / "behind.toml"
    if MPI.COMM_WORLD.rank == 0:
        scene.write_text(
            "[run]\nend_time = 1e-6\n[mesh]\nshape = 'bar'\nsize = [0.001, 0.001, 0.01]\n"
            "element_size = 0.001\n[material]\nmodel = 'linear_elastic'\ndensity = 7850.0\n"
            "young = 210e9\npoisson = 0.3\n[[wall]]\nkind = 'plane'\npoint = [0, 0, 0]\n"
            "normal_point = [0, 0, -1]\n[output]\nplot = false\n"
        )
    MPI.COMM_WORLD.Barrier()
    capsys.readouterr()  # what the logger said of the run above (set up by an earlier main())
    assert main(["run", str(scene), "--out", str(shared_dir / "cli"), "--quiet"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    if MPI.COMM_WORLD.rank == 0:
        assert err == [f"rwall-fem: warning: {warning}"]
        assert f"warning: {warning}" in (shared_dir / "cli" / "run.log").read_text()
        summary = json.loads((shared_dir / "cli" / "summary.json").read_text())
        assert summary["walls"][0]["initially_penetrated"] == 4 * N


def test_a_wall_without_secondary_nodes_is_reported(shared_dir):
    raw = bar_scene(elements=N, h=H)
    raw["wall"][0] |= {"point": [0.0, 0.0, -1.0], "secondary": {"search_distance": 0.1}}
    sim = run(raw, shared_dir)
    assert sim.history.summary["walls"][0]["secondary_nodes"] == 0
    assert sim.history.summary["warnings"] == [
        "wall[0]: no secondary node; the wall acts on nothing (widen "
        "secondary.search_distance, or add node sets)"
    ]


def test_a_node_both_clamped_and_secondary_is_reported(shared_dir):
    raw = bar_scene(elements=N, h=H)
    raw["boundary"] = [{"group": "bottom", "components": "z"}]
    sim = run(raw, shared_dir)
    assert sim.history.summary["warnings"] == [
        "boundary[0] prescribes components z of 4 nodes that are also secondary to wall[0]: "
        "on those components the boundary condition wins (it acts after the walls), on the "
        "others the wall acts"
    ]
    assert sim.constraints[-1].name == "boundary[0]"  # it acts last
