"""The results folder of a run: checked before meshing, locked while the run writes.

- :func:`check_folder` finds, without writing anything, whether a folder can be made or
  written to (a file in its place, a read-only parent): before the mesh is built, so
  that a run does not mesh for minutes and then fail to write.
- :class:`ResultsFolder` is held while a run writes: rank 0 creates the lock file
  ``.rwall-fem.lock`` atomically (a second run into the same folder is refused in one
  line), removes the outputs an earlier run left there (:data:`STALE`: they would mix
  with this run's; a resumed run continues them instead, and a fresh run drops an
  earlier checkpoint itself), and removes the lock when the run ends, however it ends.
  A lock left by a killed run on this host is taken over once its process is gone.

Every rank learns rank 0's outcome (one broadcast), so all of them refuse alike.
"""

from __future__ import annotations

import errno
import os
import shutil
import socket
import tempfile
import time
from pathlib import Path

from rwall_fem import interrupts
from rwall_fem.scene import SceneError

__all__ = ["LOCK", "STALE", "ResultsFolder", "check_folder"]

LOCK = ".rwall-fem.lock"
# What a run writes; whatever of it an earlier run left is removed when a run starts.
STALE = (
    "summary.json", "energy.csv", "walls.csv", "histories.png", "run.log", "fields.xdmf",
    "fields.h5", "animation.gif", "animation.mp4", "frames", "contacts.csv",
)  # fmt: skip


def check_folder(directory: Path, what: str, comm) -> None:
    """Raise :class:`SceneError` on every rank if ``directory`` cannot hold the results
    (``what`` names where it came from: "output.directory" or "--out"). Writes nothing:
    a probe folder made in the nearest existing parent is removed at once."""
    error = None
    if comm.rank == 0:
        error = _unusable(Path(directory))
    error = comm.bcast(error, root=0)
    if error:
        raise SceneError(f"{what}: {error}; choose another folder (--out or output.directory)")


def _unusable(directory: Path) -> str | None:
    """Why ``directory`` cannot hold results, or None."""
    directory = directory.absolute()
    existing = directory
    while not existing.exists() and existing != existing.parent:
        if existing.is_symlink():  # a dangling link
            return f"{existing} is a broken symbolic link"
        existing = existing.parent
    if not existing.is_dir():
        return f"{existing} is not a folder" + (" (a file)" if existing.is_file() else "")
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".rwall-fem-probe-", dir=existing))
    except OSError as err:
        verb = "write in" if existing == directory else f"create {directory} in"
        return f"cannot {verb} {existing} ({err.strerror})"
    return None


class ResultsFolder:
    """Context manager that holds ``directory`` for one run on ``comm`` (see the module);
    ``fresh``: the run starts at step 0 (not a resume), so an earlier run's outputs go.

    :attr:`removed` lists the outputs of an earlier run that were removed (rank 0).
    """

    def __init__(self, directory: Path, comm, *, fresh: bool = True):
        self.directory, self.comm, self.fresh = Path(directory), comm, fresh
        self.lock = self.directory / LOCK
        self.removed: list[str] = []
        self._emergency = None

    def __enter__(self) -> ResultsFolder:
        error = None
        if self.comm.rank == 0:
            try:
                if self.fresh:
                    self.directory.mkdir(parents=True, exist_ok=True)
                elif not self.directory.is_dir():  # a resume makes nothing
                    raise FileNotFoundError(errno.ENOENT, "no such folder, nothing to resume")
                error = self._take_lock()
            except OSError as err:
                verb = "create" if self.fresh else "resume in"
                error = f"cannot {verb} {self.directory} ({err.strerror})"
            if error is None:
                # A stop signal while a long C call holds the main thread: the watcher
                # ends the process, and removes the lock first.
                self._emergency = interrupts.on_emergency(self._drop_lock)
                self._emergency.__enter__()
                try:
                    if self.fresh:
                        self.removed = self._remove_stale()
                except BaseException:
                    self.__exit__()
                    raise
        error = self.comm.bcast(error, root=0)
        if error:
            raise SceneError(error)
        return self

    def __exit__(self, *exc) -> bool:
        if self.comm.rank == 0:
            self._drop_lock()
            if self._emergency is not None:
                self._emergency.__exit__(None, None, None)
                self._emergency = None
        return False

    def _drop_lock(self, reason: str | None = None) -> None:
        self.lock.unlink(missing_ok=True)

    def _take_lock(self) -> str | None:
        """Create the lock file (atomically); None, or why the folder is in use."""
        owner = f"{os.getpid()} {socket.gethostname()} {time.strftime('%Y-%m-%d %H:%M:%S')}"
        for _ in range(2):
            try:
                fd = os.open(self.lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                if not self._left_by_a_dead_run():
                    break
                self.lock.unlink(missing_ok=True)
                continue
            with os.fdopen(fd, "w") as file:
                file.write(owner + "\n")
            return None
        try:
            pid, host, *since = self.lock.read_text().split()
            holder = f"run {pid} on {host} since {' '.join(since)}"
        except (OSError, ValueError):
            holder = "another run"
        return (
            f"{self.directory} is in use by {holder} (lock file {self.lock}); wait for "
            "it to end or choose another --out (remove the lock file if no run uses it)"
        )

    def _left_by_a_dead_run(self) -> bool:
        """Whether the lock names a process of this host that no longer exists."""
        try:
            pid, host, *_ = self.lock.read_text().split()
            if host != socket.gethostname():
                return False
            os.kill(int(pid), 0)
        except ProcessLookupError:
            return True
        except (OSError, ValueError):  # unreadable, or a process of another user
            return False
        return False

    def _remove_stale(self) -> list[str]:
        """Remove the outputs of an earlier run; returns their names."""
        removed = []
        for name in STALE:
            path = self.directory / name
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            elif path.exists() or path.is_symlink():
                path.unlink()
            else:
                continue
            removed.append(name)
        return removed
