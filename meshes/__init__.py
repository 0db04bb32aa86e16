"""The gmsh geometry of the built-in shapes (``mesh.shape`` in a scene).

Open and edit the ``.geo`` files here with gmsh. pyproject.toml installs this folder
as the package ``rwall_fem.meshes``, so that the shapes work from an installed wheel;
:mod:`rwall_fem.meshing` finds the files through ``importlib.resources``.
"""

__all__: list[str] = []
