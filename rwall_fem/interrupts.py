"""SIGINT (Ctrl-C) and SIGTERM at every stage of a command, outside the time loop.

In the time loop a stop signal only asks the ranks to stop together at a step
(:mod:`rwall_fem.solver`, :mod:`rwall_fem.output.history`). Everywhere else (importing,
meshing, compiling, building, finishing the outputs and drawing the pictures after the
loop, ``render``, ``study``) the command line holds :func:`handling`, and the first
signal

1. stops the child processes of the command (the C compiler and what it runs, the
   renderer, the drawing of ``histories.png``): SIGTERM, then SIGKILL to what is left
   after :data:`CHILD_SECONDS`, so that none of them writes on after its parent;
2. raises :class:`Interrupted` in the main thread, so that ``finally`` blocks and context
   managers undo what was in progress (a temporary folder, the results folder's lock);
   the command then ends with one line, ``rwall-fem: stopped: interrupted (SIGINT,
   Ctrl-C)`` or ``... terminated by SIGTERM``, and exit code 3.

Python sees a signal only between two of its instructions: a long call into C code
(gmsh meshing, an MPI collective waiting for a rank that has already stopped) hides it.
A watcher thread, woken by the signal through a wake-up pipe, therefore ends the process
itself (the cleanups registered with :func:`on_emergency`, the same line, exit code 3)
when the main thread has not finished within :data:`GRACE_SECONDS`, or at once inside
:func:`at_once` (meshing, where nothing needs undoing: Open MPI's ``mpirun`` kills its
ranks one second after it passes SIGTERM on).

This module imports nothing heavy: the renderer, which must not load DOLFINx, uses it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from pathlib import Path

__all__ = [
    "CHILD_SECONDS",
    "GRACE_SECONDS",
    "Interrupted",
    "adopt",
    "at_once",
    "deferred",
    "handling",
    "leave",
    "on_emergency",
    "stop_children",
]

# Wall time a child has to end after SIGTERM, before SIGKILL (s): short, because Open MPI's
# mpirun kills a rank 1 s after it passes SIGTERM on, and the rank must say why first; the
# children write their files whole (rwall_fem.output.atomic), so SIGKILL cuts none.
CHILD_SECONDS = 0.25
GRACE_SECONDS = 3.0  # wall time the main thread has to end after a signal, s
LINGER_SECONDS = 0.3  # wall time a rank other than 0 leaves rank 0 to say why, s
SIGNALS = (signal.SIGINT, signal.SIGTERM)
REASONS = {"SIGINT": "interrupted (SIGINT, Ctrl-C)", "SIGTERM": "terminated by SIGTERM"}
_RANK_VARIABLES = ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK")


class Interrupted(KeyboardInterrupt):
    """A stop signal outside the time loop. A KeyboardInterrupt, so that code that cleans
    up after Ctrl-C does so after SIGTERM too; :attr:`reason` is the line's text."""

    def __init__(self, name: str):
        super().__init__(name)
        self.signal = name
        self.reason = REASONS[name]

    def __str__(self) -> str:
        return self.reason


# Children started in a session of their own (outside this process group), by pid.
_ADOPTED: set[int] = set()


class _Handling:
    """The installed handlers, the wake-up pipe and its watcher (one per process)."""

    def __init__(self):
        self.received: str | None = None
        self.cleanups: list = []
        self.abrupt = 0  # depth of at_once() regions
        self.deferring = 0  # depth of deferred() regions
        self.ended = threading.Event()
        self._said = threading.Lock()
        self._read, self._write = os.pipe()
        os.set_blocking(self._write, False)
        self._previous_fd = signal.set_wakeup_fd(self._write, warn_on_full_buffer=False)
        self._previous = {number: signal.signal(number, self._raise) for number in SIGNALS}
        threading.Thread(target=self._watch, name="rwall-fem-signals", daemon=True).start()

    def restore(self) -> None:
        for number, handler in self._previous.items():
            signal.signal(number, handler)
        signal.set_wakeup_fd(self._previous_fd)
        self.ended.set()
        os.close(self._write)  # the watcher reads the end of the pipe and returns

    def _raise(self, signum, frame) -> None:
        name = signal.Signals(signum).name
        if self.received is not None:  # a second signal while the first is handled
            return
        self.received = name
        stop_children()
        if not self.deferring:
            raise Interrupted(name)

    def _watch(self) -> None:
        while True:
            try:
                byte = os.read(self._read, 1)
            except OSError:
                byte = b""
            if not byte:
                os.close(self._read)
                return
            number = byte[0]
            # In the time loop its own handler is in place: the run stops at a step.
            if number not in SIGNALS or signal.getsignal(number) != self._raise:
                continue
            name = signal.Signals(number).name
            started = time.monotonic()
            while not self.ended.is_set():
                if self.abrupt or time.monotonic() - started > GRACE_SECONDS:
                    self._emergency(self.received or name)
                self.ended.wait(0.05)

    def _emergency(self, name: str) -> None:
        """End the process from the watcher thread: the main thread is stuck in C code."""
        stop_children()
        reason = REASONS[name]
        for cleanup in reversed(self.cleanups):
            with contextlib.suppress(Exception):
                reason = cleanup(reason) or reason
        self.say(reason)
        leave(3)

    def say(self, reason: str) -> None:
        """The one line, from rank 0, once."""
        if not self._said.acquire(blocking=False):
            return
        if rank() == 0:
            print(f"rwall-fem: stopped: {reason}", file=sys.stderr, flush=True)


_ACTIVE: _Handling | None = None


@contextlib.contextmanager
def handling():
    """Hold the handlers of this module (main thread only; re-entrant: an inner use is
    the outer one). Yields a function that prints the one line of an
    :class:`Interrupted` (rank 0, once: the watcher may have said it)."""
    global _ACTIVE
    if _ACTIVE is not None or threading.current_thread() is not threading.main_thread():
        yield _ACTIVE.say if _ACTIVE is not None else _say
        return
    _ACTIVE = _Handling()
    try:
        yield _ACTIVE.say
    finally:
        active, _ACTIVE = _ACTIVE, None
        active.restore()


def _say(reason: str) -> None:
    if rank() == 0:
        print(f"rwall-fem: stopped: {reason}", file=sys.stderr, flush=True)


@contextlib.contextmanager
def at_once():
    """A region where a signal ends the process at once (from the watcher thread, if the
    main thread is in C code): nothing in it needs undoing."""
    if _ACTIVE is None:
        yield
        return
    active = _ACTIVE
    active.abrupt += 1
    try:
        yield
    finally:
        active.abrupt -= 1


@contextlib.contextmanager
def deferred():
    """A region that a signal does not cut: :class:`Interrupted` is raised when it ends
    (the watcher still ends the process if it lasts beyond :data:`GRACE_SECONDS`). For
    objects whose destructor fails when a signal leaves them half made or half closed,
    e.g. a VTK render window."""
    if _ACTIVE is None:
        yield
        return
    active, before = _ACTIVE, _ACTIVE.received
    active.deferring += 1
    try:
        yield
    finally:
        active.deferring -= 1
    if before is None and active.received is not None and not active.deferring:
        raise Interrupted(active.received)


@contextlib.contextmanager
def on_emergency(cleanup):
    """Run ``cleanup(reason)`` (quick, no MPI) if the watcher must end the process while
    this region is held, e.g. remove a lock file that the ``finally`` blocks would remove;
    ``reason`` is the text of the line, which the cleanup may return extended."""
    active = _ACTIVE
    if active is None:
        yield
        return
    active.cleanups.append(cleanup)
    try:
        yield
    finally:
        active.cleanups.remove(cleanup)


def leave(code: int) -> None:
    """End this process now, without MPI's finalisation (another rank may be anywhere, even
    in a collective call that would keep this one there for ever; the launcher ends the
    others). A rank other than 0 waits :data:`LINGER_SECONDS` first: Open MPI's ``mpirun``
    stops passing on the output of rank 0 once another rank has ended."""
    sys.stdout.flush()
    sys.stderr.flush()
    if rank() != 0:
        time.sleep(LINGER_SECONDS)
    os._exit(code)


def adopt(pid: int) -> None:
    """Count the process ``pid``, started in a session of its own, among the children
    that :func:`stop_children` stops (those of this process group are found alone)."""
    _ADOPTED.add(pid)


def rank() -> int:
    """This process's MPI rank, as the launcher says (0 without one): the watcher thread
    must not call MPI while the main thread may be in it."""
    for name in _RANK_VARIABLES:
        if os.environ.get(name, "").isdigit():
            return int(os.environ[name])
    return 0


def stop_children(seconds: float = CHILD_SECONDS) -> None:
    """SIGTERM to every descendant of this process in its process group or in the group
    of an adopted child, then SIGKILL to those still there after ``seconds``. The MPI
    daemon that Open MPI starts beside a singleton is in a session of its own: left."""
    deadline = time.monotonic() + seconds
    sent: set[int] = set()
    while True:
        alive = _descendants()
        for pid in alive - sent:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGTERM)
        sent |= alive
        if not alive or time.monotonic() > deadline:
            break
        time.sleep(0.02)
    for pid in alive:
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)
    _ADOPTED.intersection_update(_descendants())


def _descendants() -> set[int]:
    """Living (not zombie) descendants of this process to stop, by pid (Linux /proc;
    elsewhere the adopted children only)."""
    table = {}
    try:
        entries = [p for p in os.listdir("/proc") if p.isdigit()]
    except OSError:
        return {pid for pid in _ADOPTED if _exists(pid)}
    for entry in entries:
        try:
            text = Path(f"/proc/{entry}/stat").read_text()
        except OSError:  # gone meanwhile
            continue
        fields = text[text.rindex(")") + 2 :].split()
        table[int(entry)] = (fields[0], int(fields[1]), int(fields[2]))  # state, ppid, pgrp
    groups = {os.getpgrp(), *_ADOPTED}
    found, frontier = set(), [os.getpid()]
    while frontier:
        parent = frontier.pop()
        for pid, (state, ppid, group) in table.items():
            if ppid == parent and pid not in found:
                frontier.append(pid)
                if state != "Z" and (group in groups or pid in _ADOPTED):
                    found.add(pid)
    return found


def _exists(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except OSError:
        return False
    return True
