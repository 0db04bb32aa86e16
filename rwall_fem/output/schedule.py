"""The steps at which a recorder samples: every k-th step, or a few spread over the run."""

from __future__ import annotations

__all__ = ["Every", "spread"]


class Every:
    """Steps 0, k, 2k, ... and the last step ``last`` (``step in Every(k, last)``)."""

    def __init__(self, k: int, last: int):
        self.k, self.last = k, last

    def __contains__(self, step: int) -> bool:
        return step % self.k == 0 or step == self.last


def spread(count: int, last: int) -> frozenset[int]:
    """``count`` steps spread evenly over 0..``last``, both ends included."""
    return frozenset(round(k * last / max(count - 1, 1)) for k in range(count))
