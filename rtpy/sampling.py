"""Random numbers and the sampling routines built on them.

rtpy never draws from Python's or numpy's global generator. The renderer gives
every unit of work (a tile and a batch of samples) its own generator, seeded by
(seed, tile, batch), and installs it with `use_generator` while that unit runs;
the functions below draw from the installed one. So an image depends only on the
seed and the settings, never on how many worker processes rendered it. With a
sampler other than "independent" (rtpy/sampler.py) the installed object is that
sampler: its random() returns the current pixel sample's next dimension.
"""

from __future__ import annotations

import math
import random
from contextlib import contextmanager

from .vec3 import Vec3

_generator = random.Random(0)


def make_generator(*key: int) -> random.Random:
    """A Mersenne-Twister generator seeded from a tuple of integers (stable across
    processes and runs: string seeds are hashed with SHA-512, not hash())."""
    return random.Random(":".join(str(int(k)) for k in key))


@contextmanager
def use_generator(generator: random.Random):
    """Make `generator` the source of random_double() and friends inside the block."""
    global _generator
    previous = _generator
    _generator = generator
    try:
        yield generator
    finally:
        _generator = previous


def generator() -> random.Random:
    """The generator in use now."""
    return _generator


def random_double(lo: float = 0.0, hi: float = 1.0) -> float:
    """Uniform in [lo, hi)."""
    return lo + (hi - lo) * _generator.random()


def uniform_sphere(r1: float, r2: float) -> tuple[float, float, float]:
    """Maps two uniform numbers in [0, 1) to a point uniform on the unit sphere."""
    z = 1.0 - 2.0 * r1
    s = math.sqrt(max(0.0, 1.0 - z * z))
    phi = 2.0 * math.pi * r2
    return s * math.cos(phi), s * math.sin(phi), z


def cone_angle(r1: float, cone_size: float) -> tuple[float, float]:
    """(cos theta, sin^2 theta) of a direction uniform by solid angle in a cone whose
    half-angle has 1 - cos = cone_size: cos theta uniform in [1 - cone_size, 1] (pbrt-v4's
    SampleUniformCone)."""
    cos_t = 1.0 - r1 * cone_size
    return cos_t, max(0.0, 1.0 - cos_t * cos_t)


def cone_pdf(cone_size: float) -> float:
    """The solid-angle density of directions uniform in a cone of 1 - cos = cone_size:
    1 / (2 pi cone_size)."""
    return 1.0 / (2.0 * math.pi * cone_size)


def random_unit_vector() -> Vec3:
    """Uniform on the unit sphere (pdf 1 / (4 pi) per steradian)."""
    r = _generator.random
    return Vec3(*uniform_sphere(r(), r()))


def random_in_unit_disk() -> Vec3:
    """Uniform in the unit disk of the z = 0 plane."""
    r = _generator.random
    r1 = r()
    return Vec3(*disk_point(r1, r()), 0.0)


def disk_point(r1: float, r2: float) -> tuple[float, float]:
    """(x, y) uniform in the unit disk from two uniform numbers: radius sqrt(r1),
    angle 2 pi r2."""
    radius = math.sqrt(r1)
    phi = 2.0 * math.pi * r2
    return radius * math.cos(phi), radius * math.sin(phi)


def random_cosine_direction() -> Vec3:
    """A direction in the z-up hemisphere with pdf cos(theta) / pi, as local coordinates
    (x, y, z) (ONB(axis).to_world turns it around an axis)."""
    r = _generator.random
    r1 = r()
    r2 = r()
    phi = 2.0 * math.pi * r1
    s = math.sqrt(r2)
    return Vec3(s * math.cos(phi), s * math.sin(phi), math.sqrt(1.0 - r2))  # r2 < 1


def power_heuristic(pdf_a: float, pdf_b: float) -> float:
    """Veach's power heuristic (beta = 2): MIS weight of a sample drawn with pdf_a
    when the same direction could also have come from the strategy with pdf_b."""
    a2 = pdf_a * pdf_a
    total = a2 + pdf_b * pdf_b
    return a2 / total if total > 0.0 else 0.0
