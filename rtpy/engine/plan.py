"""The plan of a render: passes over the whole image, cut into units of work.

A render runs in passes; each pass gives every pixel more samples, so an image of
the whole frame exists from the end of the first pass on. The passes hold 1, 1, 2,
4, 8, ... samples per pixel, each as many as all the passes before it, up to a cap
(`max_pass_spp`, or more where one pass over a small image would not fill a unit);
after that every pass holds the cap, and the last one what is left of spp. So the
first image comes after one sample per pixel, and a stop loses at most the pass in
progress, which is never longer than the time already spent (and, past the cap,
a small share of a long render).

A pass is cut into units of at most `paths_per_unit` camera paths (a backend's
size: a unit takes about as long whatever the image size and spp, so the progress
bar moves often): bands of whole rows of equal height or, where one row holds more
paths than a unit, each row into pieces of equal width.

The plan depends on the image size, spp and the backend's unit size only, never on
the number of workers or the time: each unit draws from its own generator, seeded
by (seed, region, pass), and its sums are added in pass order (rtpy.engine.pixel_sums), so
the image depends on the seed and the options alone. The passes do not depend on
spp either (only where the last one ends), so the first k passes of a render are
those of the render of fewer samples: a render stopped after them is, bit for bit,
the render of that many samples per pixel.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from functools import lru_cache

MAX_PASS_SPP = 16  # the passes grow to this many samples per pixel


@dataclass(frozen=True)
class Unit:
    """Samples `spp` samples per pixel of the pixels x0 <= i < x1, y0 <= j < y1:
    region `region` of pass `batch`. Its samples are the samples first_sample,
    first_sample + 1, ... of each pixel (the samplers need to know which)."""

    region: int
    batch: int
    x0: int
    y0: int
    x1: int
    y1: int
    spp: int
    first_sample: int = 0

    @property
    def paths(self) -> int:
        """The camera paths the unit traces."""
        return (self.x1 - self.x0) * (self.y1 - self.y0) * self.spp


def pass_sizes(spp: int, cap: int) -> list[int]:
    """The samples per pixel of each pass: 1, 1, 2, 4, ... (each pass as many as the
    passes before it), at most `cap`, adding up to spp."""
    sizes, total = [], 0
    while total < spp:
        size = min(max(total, 1), cap, spp - total)
        sizes.append(size)
        total += size
    return sizes


class Plan:
    """The passes of a render of width x height pixels with spp samples each, cut into
    units of at most paths_per_unit paths (a pass of s samples per pixel holds units
    of paths_per_unit // s pixels, or of one pixel)."""

    def __init__(
        self,
        width: int,
        height: int,
        spp: int,
        paths_per_unit: int,
        max_pass_spp: int = MAX_PASS_SPP,
    ) -> None:
        self.width, self.height, self.spp = width, height, spp
        self.paths_per_unit = paths_per_unit
        # A pass over a small image holds as many samples as fill one unit.
        self.cap = max(max_pass_spp, paths_per_unit // (width * height))
        self.passes = pass_sizes(spp, self.cap)
        self.first_samples = [0]  # the samples before each pass
        for size in self.passes:
            self.first_samples.append(self.first_samples[-1] + size)

    def samples_after(self, passes: int) -> int:
        """The samples per pixel the first `passes` passes hold."""
        return self.first_samples[passes]

    def passes_holding(self, samples: int) -> int | None:
        """How many whole passes hold `samples` samples per pixel, or None if no
        number of them does."""
        return self.first_samples.index(samples) if samples in self.first_samples else None

    def regions(self, pass_spp: int) -> list[tuple[int, int, int, int]]:
        """The regions (x0, y0, x1, y1) of a pass of pass_spp samples per pixel."""
        return _regions(self.width, self.height, max(1, self.paths_per_unit // pass_spp))

    def units_of(self, batch: int) -> list[Unit]:
        """The units of pass `batch`, in order."""
        spp, first = self.passes[batch], self.first_samples[batch]
        return [Unit(r, batch, *box, spp, first) for r, box in enumerate(self.regions(spp))]

    def units(self, first_pass: int = 0) -> Iterator[Unit]:
        """Every unit of the passes from first_pass on, pass by pass (made as they are
        drawn: a long render has millions)."""
        for batch in range(first_pass, len(self.passes)):
            yield from self.units_of(batch)

    def count_units(self, first_pass: int = 0) -> int:
        """How many units the passes from first_pass on hold."""
        return sum(len(self.regions(s)) for s in self.passes[first_pass:])


@lru_cache(maxsize=64)
def _regions(width: int, height: int, pixels: int) -> list[tuple[int, int, int, int]]:
    """width x height cut into regions of at most `pixels` pixels: bands of whole rows
    or, where a row holds more, pieces of rows, as equal as whole numbers allow."""
    if pixels >= width:
        rows = _even_step(height, pixels // width)
        return [(0, y0, width, min(y0 + rows, height)) for y0 in range(0, height, rows)]
    cols = _even_step(width, pixels)
    return [
        (x0, y, min(x0 + cols, width), y + 1) for y in range(height) for x0 in range(0, width, cols)
    ]


def _even_step(length: int, at_most: int) -> int:
    """The step that cuts `length` into the fewest pieces of at most `at_most`, with
    sizes as equal as whole numbers allow (the last piece is the smallest)."""
    pieces = math.ceil(length / at_most)
    return math.ceil(length / pieces)
