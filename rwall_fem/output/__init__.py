"""What a run leaves behind: histories, guards, fields, frames and pictures.

- :mod:`~rwall_fem.output.history`: the recorder of ``energy.csv``, ``walls.csv`` and
  ``summary.json``, built from :mod:`~rwall_fem.output.energy` (the energy balance),
  :mod:`~rwall_fem.output.wall_table` (wall forces and impulses),
  :mod:`~rwall_fem.output.guards` (when a run must stop),
  :mod:`~rwall_fem.output.tables` (CSV files written as whole lines) and
  :mod:`~rwall_fem.output.summary`;
- :mod:`~rwall_fem.output.fields` (``fields.xdmf``), :mod:`~rwall_fem.output.frames`
  (frame data) and :mod:`~rwall_fem.output.render` (pictures, in a process without
  DOLFINx, with :mod:`~rwall_fem.output.coloring` and :mod:`~rwall_fem.output.view`);
  :mod:`~rwall_fem.output.plots` (``histories.png``);
  :mod:`~rwall_fem.output.progress` (the command line's progress bar);
- :mod:`~rwall_fem.output.run_log` (``run.log`` and the cycle lines of batch runs);
- :mod:`~rwall_fem.output.folder`: the results folder, checked before meshing and locked
  while a run writes;
- :mod:`~rwall_fem.output.schedule`: the steps at which recorders sample.

Importing this package imports nothing heavy: ``python -m rwall_fem.output.render``
must run without DOLFINx.
"""

__all__ = ["OutputError"]


class OutputError(RuntimeError):
    """An output of a finished run could not be written (the others were)."""
