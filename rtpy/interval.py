"""Interval: a closed range [min, max] of ray parameters or values."""

from __future__ import annotations

import math


class Interval:
    __slots__ = ("min", "max")

    def __init__(self, min: float = math.inf, max: float = -math.inf) -> None:
        # The default interval is empty (min > max), as in RTIOW.
        self.min = min
        self.max = max

    def size(self) -> float:
        return self.max - self.min

    def contains(self, x: float) -> bool:
        """min <= x <= max."""
        # BEGIN SOLUTION week03: min <= x <= max
        return self.min <= x <= self.max
        # END SOLUTION

    def surrounds(self, x: float) -> bool:
        """min < x < max (strictly inside)."""
        # BEGIN SOLUTION week03: min < x < max
        return self.min < x < self.max
        # END SOLUTION

    def clamp(self, x: float) -> float:
        """x moved into [min, max]: min below it, max above it."""
        # BEGIN SOLUTION week03: x clamped into [min, max]
        if x < self.min:
            return self.min
        if x > self.max:
            return self.max
        return x
        # END SOLUTION

    def is_empty(self) -> bool:
        return not self.min <= self.max

    def __repr__(self) -> str:
        return f"Interval({self.min!r}, {self.max!r})"

    @staticmethod
    def empty() -> Interval:
        return Interval(math.inf, -math.inf)

    @staticmethod
    def universe() -> Interval:
        return Interval(-math.inf, math.inf)
