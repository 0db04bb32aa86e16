"""Shells: bodies of surface meshes (quadrilaterals or triangles in 3-D), six degrees of
freedom per node.

- :mod:`rwall_fem.shells.elements`: the shell element technologies and their compiled
  forces and moments;
- :mod:`rwall_fem.shells.inertia`: the nodes' lumped masses and rotational inertias;
- :mod:`rwall_fem.shells.body`: the body of shell parts, the internal force of the step
  pipeline, with the nodes' angular velocities;
- :mod:`rwall_fem.shells.update`: central differences on translations and rotations;
- :mod:`rwall_fem.shells.loads`: loads and damping on shells;
- :mod:`rwall_fem.shells.rigid`: the rotations of a rigid body's shell nodes;
- :mod:`rwall_fem.shells.build`: a scene's shell body, for :mod:`rwall_fem.build`.
"""

__all__: list[str] = []
