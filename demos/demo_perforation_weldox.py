# # Perforation of a steel plate: residual velocities against the experiment
#
# A 197 g projectile with a hemispherical nose, 20 mm across, strikes a 12 mm plate of
# Weldox 460 E clamped on a circle of 500 mm (the scene `demos/perforation_weldox.toml`):
# the experiment of Borvik, Langseth, Hopperstad and Malo (2002, Part I). The projectile
# is a rigid sphere carried by a main node of its mass; the plate is Johnson-Cook steel
# with Johnson-Cook's damage, its failed cells eroded. This demo runs the scene at a few
# impact speeds, reads the projectile's residual velocity from the summary, and draws the
# residual velocity curve beside the experiment's. It illustrates
#
# - reading a mesh file (`demos/perforation_plate.geo`) with parameters of one's own
#   and passing it to `build_simulation` as the body,
# - overriding keys of a scene (the impact speed),
# - the erosion outputs of a run (`summary["erosion"]`, `eroded_internal`).
#
# Run it with `python demos/demo_perforation_weldox.py` (1 mm cells at the impact, about
# 80,000 hexahedra: a few minutes per speed on 2 ranks), or
# `PERFORATION_ELEMENT_SIZE=3e-3 python demos/demo_perforation_weldox.py` for a look in a
# minute.

# +
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

import rwall_fem
from rwall_fem.meshing import read_mesh

# -

# ## The experiment
# Borvik et al. (2002, Part I) give the ballistic limit of the hemispherical noses on
# these plates as about 300 m/s, some 60 % above the 185 m/s of blunt ones. Above it, a
# rigid projectile that pushes no plug along keeps the kinetic energy the plate does not
# absorb, v_r = (v_i^2 - v_bl^2)^(1/2) (Recht and Ipson's relation with a = 1, p = 2); a
# plug carried along (a < 1) lowers it: the curve is the experiment's upper bound.

BALLISTIC_LIMIT = 300.0  # m/s, the experiment's


def recht_ipson(v, limit, a=1.0, p=2.0):
    """Residual velocity (m/s) at impact velocity ``v`` (m/s) above the ``limit``."""
    return a * np.maximum(np.asarray(v, float) ** p - limit**p, 0.0) ** (1.0 / p)


# ## The runs
# The element size at the impact point comes from the environment; the plate's layers
# through the thickness follow it.

here = Path(__file__).parent
size = float(os.environ.get("PERFORATION_ELEMENT_SIZE", "1e-3"))
speeds = [float(v) for v in os.environ.get("PERFORATION_SPEEDS", "300 350 400 450").split()]
comm = MPI.COMM_WORLD
results = []
for speed in speeds:
    scene = rwall_fem.load_scene(
        here / "perforation_weldox.toml",
        [f"wall[0].motion.velocity=[0, 0, {-speed}]", "output.frames=0", "output.plot=false"],
    )
    body = read_mesh(comm, here / "perforation_plate.geo", {"h_impact": size})
    out = Path(f"results/demo_perforation_weldox/{speed:.0f}")
    sim = rwall_fem.build_simulation(scene, comm, out, body=body)
    sim.run()
    summary = sim.history.summary
    wall = summary["walls"][0]
    free = wall["last_contact"] < summary["time"] - 10 * summary["dt"]  # it has left
    residual = max(-wall["velocity"][2], 0.0) if free else 0.0  # 0: stopped, or bounced
    results.append((speed, residual, summary["erosion"]["eroded_cells"], summary["cells"]))
    if comm.rank == 0:
        eroded = summary["erosion"]["eroded_cells"]
        print(f"{speed:5.0f} m/s: residual {residual:5.1f} m/s, {eroded} cells eroded")

# ## Our ballistic limit
# Fitting Recht and Ipson's relation (a = 1, p = 2) to the perforating runs gives the
# model's ballistic limit, v_bl^2 = mean(v_i^2 - v_r^2).

perforated = [(v, r) for v, r, _, _ in results if r > 0.0]
limit = float(np.sqrt(np.mean([v**2 - r**2 for v, r in perforated]))) if perforated else None
if comm.rank == 0:
    print(f"ballistic limit: model {limit:.0f} m/s, experiment about {BALLISTIC_LIMIT:.0f} m/s")

# ## The residual velocity curve

if comm.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    v = np.linspace(0.0, max(speeds) * 1.05, 200)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    bound = f"experiment's ballistic limit {BALLISTIC_LIMIT:.0f} m/s, a = 1, p = 2"
    ax.plot(v, recht_ipson(v, BALLISTIC_LIMIT), "k--", label=bound)
    if limit is not None:
        fit = f"fit to the runs: {limit:.0f} m/s"
        ax.plot(v, recht_ipson(v, limit), color="tab:blue", lw=0.8, label=fit)
    ours = f"rwall_fem, {size * 1e3:g} mm at the impact"
    ax.plot([r[0] for r in results], [r[1] for r in results], "o", color="tab:blue", label=ours)
    ax.set_xlabel("impact velocity (m/s)")
    ax.set_ylabel("residual velocity (m/s)")
    ax.set_xlim(0.0, v[-1])
    ax.set_ylim(0.0, None)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("12 mm Weldox 460 E, 20 mm hemispherical nose, 197 g")
    path = Path("results/demo_perforation_weldox/residual_velocity.png")
    fig.savefig(path, dpi=120, bbox_inches="tight")
    print(f"wrote {path}")
