# # A steel bar strikes a rigid wall: rwall_fem from Python
#
# This demo shows the Python API on a mesh of one's own: any distributed
# DOLFINx mesh of tetrahedra or hexahedra can be struck against rigid walls.
# It illustrates
#
# - building the body from a `dolfinx.mesh` instead of the scene's `[mesh]`,
# - describing material, initial velocity and a wall with the scene schema,
# - running and reading the histories back as NumPy arrays.
#
# Run it with `python demos/demo_bar_impact.py` (or under `mpirun -n 2`).

# +
from pathlib import Path  # noqa: I001  (mpi4py must come before dolfinx, see below)

import numpy as np
from mpi4py import MPI

import rwall_fem
from dolfinx import mesh  # after mpi4py: the PyPI wheel of DOLFINx needs MPI loaded first

# -

# ## The body
# A 10 x 10 x 100 mm bar of hexahedra, 0.1 mm above the plane z = 0.

msh = mesh.create_box(
    MPI.COMM_WORLD,
    [np.array([0.0, 0.0, 1e-4]), np.array([0.01, 0.01, 0.1001])],
    [5, 5, 50],
    mesh.CellType.hexahedron,
)
body = rwall_fem.BodyMesh(msh)

# ## The problem
# The same keys as a TOML scene, without `[mesh]`: steel at 10 m/s onto a
# fixed plane whose normal points up (from M = origin to M1 = e_z).

scene = rwall_fem.parse_scene(
    {
        "run": {"end_time": 6e-5},
        "material": {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3},
        "initial": {"velocity": [0.0, 0.0, -10.0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 12},
    },
    source="demo_bar_impact",
)

# ## Run
out = Path("results/demo_bar_impact")
sim = rwall_fem.build_simulation(scene, out=out, body=body)
sim.run()

# ## Results
# Histories come back as arrays with the columns of `energy.csv` and
# `walls.csv`; the summary is what `summary.json` holds.

energy = sim.history.energy  # time, kinetic, internal, external_work, wall_work, error
wall = sim.history.wall(0)
summary = sim.history.summary
if MPI.COMM_WORLD.rank == 0:
    mass = summary["mass"]
    print(f"{summary['cells']} cells, {summary['steps']} steps of {summary['dt']:.3g} s")
    print(f"rebound velocity {summary['final_momentum'][2] / mass:.3f} m/s (was -10)")
    print(
        f"wall impulse {summary['walls'][0]['impulse'][2]:.4g} N s, "
        f"energy balance error {summary['energy']['max_balance_error']:.1e}"
    )
    print(f"pictures in {out}/frames, animation {out}/animation.gif")
