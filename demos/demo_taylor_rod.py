# # The Taylor anvil test against published results
#
# A copper rod strikes a rigid wall at 227 m/s (the scene `demos/taylor_rod.toml`).
# This demo runs it and compares the final shape with the values published for
# this benchmark, then draws the rod's profile before and after, side by side.
# It illustrates
#
# - loading a scene file and overriding keys from Python,
# - reading the summary of an elasto-plastic run (`deformed_bounds`,
#   `max_plastic_strain`, `plastic_work`),
# - gathering the deformed nodes of every rank for a picture of one's own.
#
# Run it with `python demos/demo_taylor_rod.py` (8 cells across the radius: about a
# minute), or `TAYLOR_ELEMENT_SIZE=0.8e-3 python demos/demo_taylor_rod.py` for a
# look in seconds (4 cells across). The step follows the crushed cells.

# +
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

import rwall_fem

# -

# ## The scene
# The mesh size comes from the environment (the scene's 0.4 mm by default).

element_size = float(os.environ.get("TAYLOR_ELEMENT_SIZE", "0.4e-3"))
overrides = [f"mesh.element_size={element_size}", "output.frames=0"]
scene = rwall_fem.load_scene(Path(__file__).parent / "taylor_rod.toml", overrides)

# ## Run
out = Path("results/demo_taylor_rod")
sim = rwall_fem.build_simulation(scene, out=out)
sim.run()

# ## The final shape against published results
# Final length (mm) and mushroom (footprint) radius (mm) of this benchmark:
# converged results 21.42-21.43 and 7.22 (Foulk et al. 2021), coarse meshes
# 21.47-21.66 and 7.0-7.12 (Simo 1992: 7.12; Zienkiewicz et al. 1998: 7.11).

summary = sim.history.summary
(low, high) = summary["deformed_bounds"]
length = (high[2] - low[2]) * 1e3
radius = max(high[0], -low[0], high[1], -low[1]) * 1e3
if MPI.COMM_WORLD.rank == 0:
    step = summary["time_step"]
    print(
        f"{summary['cells']} hexahedra, {summary['steps']} steps falling from "
        f"{step['first']:.3g} s to {step['smallest']:.3g} s"
    )
    print(f"final length  {length:6.2f} mm  (published 21.42-21.66 mm)")
    print(f"mushroom radius {radius:4.2f} mm  (published 7.0-7.22 mm)")
    print(f"largest equivalent plastic strain {summary['max_plastic_strain']:.2f}")
    dissipated = summary["plastic_work"] / summary["energy"]["initial"]
    print(f"plastic work {summary['plastic_work']:.1f} J ({dissipated:.1%} of the impact energy)")

# ## The profile before and after
# Every node's distance from the axis against its height, gathered on rank 0:
# the outline is the largest distance in each layer of the initial mesh.

s = sim.state
x = s.X + s.u - s.dt * s.v  # the nodes at the last step (the state is after its update)
nodes = MPI.COMM_WORLD.gather(np.hstack([s.X, x]), root=0)
if MPI.COMM_WORLD.rank == 0:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    nodes = np.vstack(nodes) * 1e3  # mm
    layers = np.round(nodes[:, 2], 6)
    heights = np.unique(layers)
    outline = [
        (np.hypot(*nodes[layers == z][:, :2].T).max(), z,
         np.hypot(*nodes[layers == z][:, 3:5].T).max(), nodes[layers == z][:, 5].mean())
        for z in heights
    ]  # fmt: skip
    r0, z0, r1, z1 = np.array(outline).T
    figure, (before, after) = plt.subplots(1, 2, figsize=(8, 5.5), sharey=True)
    for axes, r, z, title in ((before, r0, z0, "before"), (after, r1, z1, "after 80 µs")):
        axes.fill_betweenx(z, -r, r, color="#d98c4a")
        axes.plot(r, z, "k", -r, z, "k", lw=1)
        axes.axhline(0.0, color="0.3", lw=3)
        axes.set_aspect("equal")
        axes.set_xlim(-8.5, 8.5)
        axes.set_xlabel("r (mm)")
        axes.set_title(title)
    after.axhspan(21.42, 21.66, color="tab:blue", alpha=0.3, label="published length")
    after.axvspan(7.0, 7.22, color="tab:green", alpha=0.3, label="published radius")
    after.axvspan(-7.22, -7.0, color="tab:green", alpha=0.3)
    after.legend(loc="upper right", fontsize=8)
    before.set_ylabel("z (mm)")
    figure.suptitle(f"Taylor rod, copper at 227 m/s: {length:.2f} mm long, r = {radius:.2f} mm")
    figure.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    figure.savefig(out / "profiles.png", dpi=120)
    print(f"profiles in {out / 'profiles.png'}")
