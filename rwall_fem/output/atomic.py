"""Files written whole or not at all, for writers that a stop signal may kill.

:func:`whole` yields a hidden temporary name beside the file (``.STEM.partial.SUFFIX``); the
writer writes there, and only a finished file is renamed over ``NAME``. A writer killed
midway (SIGKILL to a renderer that did not end within
:data:`rwall_fem.interrupts.CHILD_SECONDS`) leaves the earlier file, or none, and at most
the hidden partial one: never a half-written frame, animation or plot.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

__all__ = ["whole"]


@contextlib.contextmanager
def whole(path: Path) -> Iterator[Path]:
    """The temporary path to write ``path`` through; renamed over ``path`` when the block
    ends normally, removed when it raises."""
    path = Path(path)
    partial = path.with_name(f".{path.stem}.partial{path.suffix}")  # the suffix tells the format
    try:
        yield partial
        os.replace(partial, path)
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
