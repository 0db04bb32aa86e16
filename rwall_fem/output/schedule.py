"""The steps at which a recorder samples: every k-th step, or a few spread over the run."""

from __future__ import annotations

__all__ = ["Every", "spread"]


class Every:
    """Steps 0, k, 2k, ... and the last step ``last`` (``step in Every(k, last)``)."""

    def __init__(self, k: int, last: int):
        self.k, self.last = k, last

    def __contains__(self, step: int) -> bool:
        return step % self.k == 0 or step == self.last


class spread:  # noqa: N801  (used like the function it replaces: ``step in spread(n, last)``)
    """``count`` steps spread evenly over 0..``last``, both ends included: the steps
    round(k last / (count - 1)), k = 0..count-1. Membership costs the same whatever
    ``count`` is (nothing is listed)."""

    def __init__(self, count: int, last: int):
        self.count, self.last = count, last

    def __contains__(self, step: int) -> bool:
        if self.count <= 0 or not 0 <= step <= self.last:
            return False
        if self.count == 1 or self.last == 0:
            return step == 0
        gaps = self.count - 1
        k = step * gaps // self.last
        return any(
            0 <= j <= gaps and round(j * self.last / gaps) == step for j in (k - 1, k, k + 1, k + 2)
        )
