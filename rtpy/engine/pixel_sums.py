"""PixelSums: the sums of the finished units of a render, added pass by pass.

Units arrive in any order (from any number of workers, or a cluster); their sums
are added in the order of the plan's passes, so that every pixel's sum is the same,
bit for bit, whatever the order of arrival (float addition is not associative):

- `total` holds the r, g, b sums and the count of samples of every pixel, of the
  whole passes finished;
- `current` holds the units of the pass in progress that have arrived, each with
  its pass (plus one) in a fifth channel; when the pass is whole it is added to
  `total` in one array operation;
- a unit of a later pass waits until its pass is in progress.

Every change is one array operation, so a Ctrl-C that interrupts the work between
any two bytecodes leaves `total` with whole passes (every sum with its count, the
counts equal), which is what a stopped render writes (`whole_samples`, `mean`),
and `current` with units each whole or absent, told apart by their pass: what a
resumed render continues from (rtpy.engine.render_state keeps both). A preview
(`snapshot`) shows the pass in progress too.
"""

from __future__ import annotations

import numpy as np

from .plan import Plan, Unit

__all__ = ["PixelSums"]


class PixelSums:
    """The sums of a render planned by `plan`: from nothing, or from a stopped
    render's `total` (height, width, 4) of whole passes and `current` (height,
    width, 5) of units of the next pass (rtpy.engine.render_state checks them)."""

    def __init__(
        self, plan: Plan, total: np.ndarray | None = None, current: np.ndarray | None = None
    ) -> None:
        self.plan = plan
        h, w = plan.height, plan.width
        self.total = np.zeros((h, w, 4)) if total is None else total
        self._current = np.zeros((h, w, 5)) if current is None else current
        passes = plan.passes_holding(int(self.total[0, 0, 3]))
        if self.total.shape != (h, w, 4) or self._current.shape != (h, w, 5) or passes is None:
            raise ValueError(f"total and current must hold passes of the plan of {w}x{h}")
        self.passes = passes  # whole passes in total
        if current is not None:
            self._current = self.current()  # its units of the pass in progress alone
        self._added: set[int] = set(self.current_regions())
        self._waiting: dict[tuple[int, int], tuple[Unit, np.ndarray]] = {}
        self._advance()  # a state cut just before its pass was added to total

    @property
    def done(self) -> bool:
        """Every pass of the plan is added, as `total` says (a Ctrl-C between adding
        the last pass and counting it in `passes` leaves the render finished)."""
        return self.plan.passes_holding(self.whole_samples()) == len(self.plan.passes)

    def holds(self, unit: Unit) -> bool:
        """The unit's sums are added (a resumed render need not render it)."""
        return unit.batch < self.passes or (
            unit.batch == self.passes and unit.region in self._added
        )

    def add(self, unit: Unit, sums: np.ndarray) -> bool:
        """Add the sums (height, width, 3) of `unit`'s region, now or once its pass is
        in progress; True if a pass became whole. A unit added before (a unit a
        cluster ran twice, or one a resumed render had) is ignored."""
        if self.holds(unit):
            return False
        self._waiting[(unit.batch, unit.region)] = (unit, sums)
        return self._advance()

    def _advance(self) -> bool:
        """Add the units waiting for the pass in progress, and the pass to `total` once
        it is whole, as long as that goes; True if a pass became whole."""
        finished = False
        while not self.done:
            for key in [k for k in self._waiting if k[0] == self.passes]:
                self._add(*self._waiting.pop(key))
            if len(self._added) < len(self.plan.regions(self.plan.passes[self.passes])):
                break
            self.total += self._current[..., :4]  # one operation: one more whole pass
            self._current.fill(0.0)
            self.passes += 1
            self._added = set()
            finished = True
        return finished

    def _add(self, unit: Unit, sums: np.ndarray) -> None:
        shape = (*sums.shape[:2], 1)
        tagged = np.concatenate(
            [sums, np.full(shape, float(unit.spp)), np.full(shape, unit.batch + 1.0)], axis=2
        )
        self._current[unit.y0 : unit.y1, unit.x0 : unit.x1] += tagged  # one operation
        self._added.add(unit.region)

    def current_regions(self) -> list[int]:
        """The regions of the pass in progress whose units `current` holds: each region
        whole, of its pass, or absent (a part of an earlier pass that was added to
        `total` just before a Ctrl-C is not of this pass)."""
        passes = self.plan.passes_holding(self.whole_samples())  # as total says
        if passes == len(self.plan.passes):
            return []
        spp, tag = self.plan.passes[passes], passes + 1.0
        return [
            r
            for r, (x0, y0, x1, y1) in enumerate(self.plan.regions(spp))
            if self._current[y0, x0, 4] == tag and self._current[y0, x0, 3] == spp
        ]

    def current(self) -> np.ndarray:
        """`current` with only the units of the pass in progress (what a resumed
        render continues from), a new array."""
        kept = np.zeros_like(self._current)
        passes = self.plan.passes_holding(self.whole_samples())
        if passes < len(self.plan.passes):
            regions = self.plan.regions(self.plan.passes[passes])
            for r in self.current_regions():
                x0, y0, x1, y1 = regions[r]
                kept[y0:y1, x0:x1] = self._current[y0:y1, x0:x1]
        return kept

    def finish(self) -> None:
        """Drop the units waiting (after a stop)."""
        self._waiting.clear()

    def whole_samples(self) -> int:
        """The samples per pixel of the whole passes, the same in every pixel."""
        return int(self.total[0, 0, 3])

    def samples_range(self) -> tuple[int, int]:
        """The fewest and the most samples a pixel has, the pass in progress included."""
        counts = self.total[..., 3] + self._current[..., 3]
        return int(counts.min()), int(counts.max())

    def paths(self) -> int:
        """Samples added over all pixels, the pass in progress included."""
        return int((self.total[..., 3] + self._current[..., 3]).sum())

    def snapshot(self) -> np.ndarray:
        """The mean of each pixel's samples added so far, the pass in progress
        included, as a new array (black where there is none)."""
        return _divide(self.total + self._current[..., :4])

    def mean(self) -> np.ndarray:
        """The mean of each pixel's samples of the whole passes (black before the
        first), an array (height, width, 3), computed in place: `total` becomes it
        (call it once, last)."""
        self.finish()
        self._current = np.zeros((0, 0, 5))  # its memory, for the image's
        return _divide(self.total)


def _divide(total: np.ndarray) -> np.ndarray:
    """The sums of `total` (sums and counts) divided, in place, by their counts;
    black where there are none."""
    sums, counts = total[..., :3], total[..., 3:]
    np.divide(sums, counts, out=sums, where=counts > 0)
    return sums
