"""The renderer as a second process that runs beside the time loop (rank 0).

When the machine has a core more than the run's ranks use, :class:`Frames
<rwall_fem.output.frames.Frames>` starts ``python -m rwall_fem.output.render DIR --follow``
at the first frame and sends it the name of each frame file once that file is whole: while
the loop runs, the worker imports VTK and the image encoders and reads the frames. The
camera and the colour range are fitted to every frame (one view and one range for the
animation), so the drawing itself starts at ``end``, which :meth:`RenderWorker.finish`
sends when the loop is over (done, stopped or failed): the frames written so far are all
drawn.

``RWALL_FEM_RENDER=inline`` draws after the loop in a process started then (the choice
when there is no free core), ``RWALL_FEM_RENDER=worker`` starts the worker whatever the
cores. The worker is in a session of its own (a Ctrl-C at the terminal reaches the run,
which stops at a step and then lets the worker draw), adopted by
:mod:`rwall_fem.interrupts` (a stop signal outside the loop ends it, as any child); it ends
itself without writing when its parent is gone. It writes each file whole
(:mod:`rwall_fem.output.atomic`). A worker that fails or dies is replaced by the inline
renderer at the end. This module must not import DOLFINx (see
:mod:`rwall_fem.output.frames`).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

from rwall_fem import interrupts

__all__ = ["MODES", "RenderWorker", "renderer_command", "renderer_env", "wanted"]

MODES = ("auto", "worker", "inline")  # values of RWALL_FEM_RENDER


def renderer_command(directory: Path, color: str, *extra: str) -> list[str]:
    """The command line of the renderer's process for the run in ``directory``."""
    return [sys.executable, "-m", "rwall_fem.output.render", str(directory), "--color", color,
            *extra]  # fmt: skip


def renderer_env() -> dict[str, str]:
    """The renderer's environment: without the MPI launcher's variables (it is no rank),
    drawing through EGL off-screen."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    return env


def wanted(ranks: int) -> bool:
    """Whether to render beside the loop: ``RWALL_FEM_RENDER`` says so, or (``auto``, the
    default) this process may run on more cores than the ``ranks`` of the run take."""
    mode = os.environ.get("RWALL_FEM_RENDER", "auto").strip().lower() or "auto"
    if mode not in MODES:
        print(f"rwall-fem: warning: RWALL_FEM_RENDER={mode!r} is not one of {', '.join(MODES)}; "
              "auto", file=sys.stderr)  # fmt: skip
        mode = "auto"
    if mode != "auto":
        return mode == "worker"
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        cores = os.cpu_count() or 1
    return cores > ranks


class RenderWorker:
    """The renderer's process for the run in ``directory``, colouring by ``color``, fed with
    the names of the frame files as they are written."""

    def __init__(self, directory: Path, color: str):
        self._log = tempfile.TemporaryFile()  # its messages: a pipe could fill and block it
        self.process = subprocess.Popen(
            renderer_command(directory, color, "--follow", str(os.getpid())),
            stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            stderr=self._log,
            env=renderer_env(),
            start_new_session=True,
        )
        interrupts.adopt(self.process.pid)
        self.alive = True

    def send(self, name: str) -> None:
        """Tell the worker that the frame file ``name`` is whole; a worker that has ended
        is left (the inline renderer replaces it at the end)."""
        if not self.alive:
            return
        try:
            self.process.stdin.write(f"{name}\n".encode())
            self.process.stdin.flush()
        except (BrokenPipeError, OSError, ValueError):
            self.alive = False

    def finish(self) -> tuple[int, str]:
        """Send ``end``, wait for the drawing to end; returns its exit code and messages. A
        stop signal meanwhile ends the worker (:func:`rwall_fem.interrupts.stop_children`)."""
        self.send("end")
        try:
            self.process.stdin.close()
        except OSError:
            pass
        code = self.process.wait()
        self._log.seek(0)
        text = self._log.read().decode(errors="replace")
        self._log.close()
        return code, text

    def abandon(self) -> None:
        """End the worker without drawing (the frames failed to be written)."""
        try:
            self.process.stdin.close()  # EOF without ``end``: it leaves without writing
        except OSError:
            pass
        self.process.wait()
        self._log.close()
