# # A rubber sheet falls onto a rigid cylinder: rwall_fem from Python
#
# A sheet falls onto a rigid cylinder, bends over it and bounces off: large
# rotations, so the compressible neo-Hookean model instead of small strain.
# This demo illustrates
#
# - meshing one of the gmsh bodies of `meshes/` from Python (`plate_mesh`),
# - giving walls as shape objects (`CylinderWall`) with their options,
# - switching on effects (gravity, large deformation) and reading the results.
#
# Run it with `python demos/demo_plate_on_cylinder.py` (or under `mpirun -n 2`);
# `demos/plate_on_cylinder.toml` is the same problem, finer, as a scene file.

# +
from pathlib import Path  # noqa: I001  (mpi4py must come before DOLFINx)

from mpi4py import MPI

import rwall_fem  # after mpi4py: the PyPI wheel of DOLFINx needs MPI loaded first
from rwall_fem.meshing import plate_mesh

# -

# ## The body
# A 100 x 40 x 4 mm sheet of hexahedra, two through the thickness, 0.1 mm above
# the cylinder's top line. `plate_mesh` meshes `meshes/plate.geo` on rank 0 and
# distributes it; its faces come with the groups `bottom`, `top` and `sides`.

body = plate_mesh(
    MPI.COMM_WORLD,
    origin=[-0.05, -0.02, 0.0101],
    size=[0.1, 0.04, 0.004],
    element_size=0.004,
    cell="hexahedron",
    layers=2,
)

# ## The problem
# Rubber-like (5 MPa, nu = 0.45) at 5 m/s, with gravity. The wall is a shape
# object: a cylinder of 20 mm diameter whose axis runs along y through the
# origin; options (slide, friction, motion, secondary nodes) go beside it.

cylinder = rwall_fem.CylinderWall(point=[0, 0, 0], axis_point=[0, 1, 0], diameter=0.02)
scene = rwall_fem.parse_scene(
    {
        "run": {"end_time": 0.02},
        "material": {"model": "neo_hookean", "density": 1100.0, "young": 5.0e6, "poisson": 0.45},
        "initial": {"velocity": [0.0, 0.0, -5.0]},
        "gravity": {"acceleration": [0.0, 0.0, -9.81]},
        "wall": [{"shape": cylinder, "slide": "free"}],
        "output": {"frames": 10, "history_interval": 10},
    },
    source="demo_plate_on_cylinder",
)

# ## Run
out = Path("results/demo_plate_on_cylinder")
sim = rwall_fem.build_simulation(scene, out=out, body=body)
status = sim.run()

# ## Results
# The histories are arrays with the columns of `energy.csv` and `walls.csv`.
# The balance error of a nonlinear material is the integrator's O(dt^2), not
# round-off (see the README).

energy = sim.history.energy  # time, kinetic, internal, external_work, wall_work, error
wall = sim.history.wall(0)
summary = sim.history.summary
if MPI.COMM_WORLD.rank == 0:
    print(
        f"{status}: {summary['cells']} cells, {summary['steps']} steps of "
        f"{summary['dt']:.3g} s, effects {', '.join(summary['effects'])}"
    )
    print(
        f"first contact at {1e3 * summary['walls'][0]['first_contact']:.2f} ms, "
        f"peak {summary['walls'][0]['peak_contacts']} nodes on the cylinder"
    )
    print(
        f"strain energy at the end {energy[-1, 2]:.3g} J, "
        f"energy balance error {summary['energy']['max_balance_error']:.1e}"
    )
    print(f"pictures in {out}/frames, animation {out}/animation.gif")
