"""When a run must stop (the Radioss /STOP and LS-DYNA ENDENG kind of checks).

The guards act at every history sample, on values already summed over ranks, so every
rank takes the same decision at the same step: a NaN or Inf in a nodal array (seen as a
non-finite sum), an energy balance error above ``max_energy_error``, as much energy put
in by the changes of a varying step, or a SIGTERM or SIGINT (Ctrl-C) received by any rank
stop the run with one
:class:`~rwall_fem.solver.RunStopped` message naming the step, the time, the quantity
and the worst node. (What the time step stops a run for, :mod:`rwall_fem.time_step`
decides.)
"""

from __future__ import annotations

import numpy as np

from rwall_fem.solver import RunStopped

__all__ = ["Guards"]


class Guards:
    """The checks of a sample. ``node_ids`` are the global indices of the rank's owned
    nodes (for the messages); ``max_energy_error`` bounds |balance error|."""

    def __init__(self, comm, node_ids: np.ndarray, *, max_energy_error: float = 0.05):
        self.comm, self.node_ids = comm, node_ids
        self.max_energy_error = max_energy_error

    def check(
        self, s, error: float, *, finite: bool, signals: tuple[str, ...] = (), step_work=0.0
    ) -> None:
        """Raise :class:`RunStopped` (on every rank alike) if a guard trips at the sample of
        the state ``s``: ``error`` is its balance error, ``finite`` whether every sum of
        the sample is finite, ``signals`` the stop signals any rank received ("SIGTERM",
        "SIGINT"), ``step_work`` the work of the step's changes over the energy scale."""
        if finite and abs(error) <= self.max_energy_error and not signals and (
            abs(step_work) <= self.max_energy_error
        ):
            return  # nothing trips: the message is not written
        where = f"step {s.step}, t = {s.t:.6g} s"
        if not finite:
            bad = ~(np.isfinite(s.u).all(axis=1) & np.isfinite(s.v).all(axis=1))
            node = self._worst(bad.astype(float), s)
            raise RunStopped(f"{where}: NaN or Inf in the nodal state; first bad node {node}")
        if abs(error) > self.max_energy_error:
            node = self._worst(np.linalg.norm(s.v, axis=1), s, "|v| = {:.4g} m/s")
            raise RunStopped(
                f"{where}: energy balance error {error:.3g} exceeds run.max_energy_error = "
                f"{self.max_energy_error:g}; fastest node {node}"
            )
        if abs(step_work) > self.max_energy_error:
            raise RunStopped(
                f"{where}: the changes of the time step have put {100 * step_work:.3g} % of the "
                f"body's energy into it, more than run.max_energy_error = "
                f"{self.max_energy_error:g}: the step varies too fast for the body"
            )
        if "SIGTERM" in signals:
            raise RunStopped(f"{where}: terminated by SIGTERM")
        if "SIGINT" in signals:
            raise RunStopped(f"{where}: interrupted (SIGINT, Ctrl-C)")

    def _worst(self, score: np.ndarray, s, detail: str = "") -> str:
        """'<global id> at (x, y, z) m' of the node with the largest ``score`` on any rank."""
        score = np.where(np.isnan(score), np.inf, score)
        i = int(np.argmax(score)) if len(score) else -1
        mine = (score[i], self.node_ids[i], *(s.X[i] + s.u[i])) if i >= 0 else (-np.inf,)
        best = max(self.comm.allgather(mine), key=lambda c: c[0])
        text = f"{best[1]} at ({best[2]:.6g}, {best[3]:.6g}, {best[4]:.6g}) m"
        return f"{text}, {detail.format(best[0])}" if detail else text
