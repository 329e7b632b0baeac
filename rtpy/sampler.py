"""Samplers: where the uniform numbers of a pixel sample come from.

A Monte Carlo estimate of a pixel averages spp samples; each sample uses a few
uniform numbers in [0, 1), its *dimensions*: the position in the pixel (2D), the
point on the lens (2D), the light chosen at the first hit (1D), the point on that
light (2D), the direction the BRDF samples there (2D). The independent sampler draws
every number on its own, so the error falls as 1 / sqrt(spp) whatever happens. The
other two spread each dimension's spp values of a pixel evenly over [0, 1) or
[0, 1)^2, so that fewer samples land in the same place and smooth integrands
converge faster; each value on its own is still uniform, so every estimate stays
unbiased.

- independent: every value its own uniform number.
- stratified: the square is cut into a grid of strata (a sqrt(spp) x sqrt(spp)
  grid when spp is a square; otherwise the smallest grid of nx = ceil(sqrt(spp))
  columns and ceil(spp / nx) rows, of which each pixel uses spp strata chosen at
  random); sample k of a pixel takes the stratum that a random permutation (one per
  pixel and dimension) gives it, and a uniform point inside it. 1D: spp strata.
- sobol: the first two dimensions of the Sobol sequence (the van der Corput
  sequence and its companion, a (0,2)-sequence), randomized by Owen scrambling:
  every prefix of 2^m points has exactly one point in each of the 2^m elementary
  intervals of each shape (2^a x 2^b cells, a + b = m). Each dimension (1D or 2D)
  of a pixel gets its own scrambling and its own shuffle of the sample indices
  ("padding", as pbrt-v4's PaddedSobolSampler), so the dimensions are independent
  of each other and pixels are independent of each other. The scrambling is the
  hash-based nested uniform scramble of Burley, "Practical Hash-based Owen
  Scrambling", JCGT 9(4), 2020 (the generator matrices: Kollig and Keller,
  "Efficient Multidimensional Sampling", Eurographics 2002).

Everything is a function of (seed, pixel, sample index, dimension) through integer
hashes, never of the order in which pixels are rendered, so an image depends on the
seed alone, for any number of workers. rtpy.numpy_backend.sampler computes the same
values for arrays of pixels and sample indices.

Which numbers a path draws: the renderer installs the sampler with
rtpy.sampling.use_generator, and its random() hands out the draws of each pixel
sample in the order the code makes them, grouped as LAYOUT says: the pixel position
(2D), the lens (2D, only with a defocus angle), then at the first hit the light
choice (1D), the light sample (2D) and the BRDF sample (2D). Every later draw (the
next bounces, Russian roulette) is an independent number of the unit of work's
Mersenne Twister.
"""

from __future__ import annotations

import math
import random

MASK32 = 0xFFFFFFFF
MASK64 = 0xFFFFFFFFFFFFFFFF
GOLDEN = 0x9E3779B97F4A7C15  # 2^64 / golden ratio: splitmix64's increment
TWO_TO_MINUS_32 = 1.0 / (1 << 32)
TWO_TO_MINUS_53 = 1.0 / (1 << 53)
ONE_MINUS_EPSILON = 1.0 - TWO_TO_MINUS_53  # the largest float below 1

# Dimension numbers: every 1D or 2D dimension of a sample has its own.
PIXEL, LENS, LIGHT_CHOICE, LIGHT, BRDF = range(5)
# (dimension, size) of the draws random() serves, in the order paths make them.
LAYOUT = ((PIXEL, 2), (LENS, 2), (LIGHT_CHOICE, 1), (LIGHT, 2), (BRDF, 2))


def mix64(z: int) -> int:
    """splitmix64's finalizer (Steele, Lea and Flood 2014): a bijection of 64-bit
    integers whose output bits each depend on every input bit."""
    z = (z + GOLDEN) & MASK64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK64
    return z ^ (z >> 31)


def hash_key(*key: int) -> int:
    """A 64-bit hash of a tuple of non-negative integers."""
    h = 0
    for k in key:
        h = mix64(h ^ (k & MASK64))
    return h


def unit_float(h: int) -> float:
    """A number in [0, 1) from the top 53 bits of a 64-bit hash."""
    return (h >> 11) * TWO_TO_MINUS_53


def jittered(k: int, u: float, n: int) -> float:
    """The point u in [0, 1) of stratum k of n strata of [0, 1): (k + u) / n, which
    rounds to 1.0 for k = n - 1 and u just below 1, kept below 1."""
    return min((k + u) / n, ONE_MINUS_EPSILON)


_REVERSED_BYTE = [int(f"{b:08b}"[::-1], 2) for b in range(256)]


def reverse_bits32(v: int) -> int:
    """The 32 bits of v in reverse order (byte by byte, each byte mirrored)."""
    r = _REVERSED_BYTE
    return r[v & 255] << 24 | r[v >> 8 & 255] << 16 | r[v >> 16 & 255] << 8 | r[v >> 24 & 255]


def owen_scramble(v: int, seed: int) -> int:
    """Burley's hash-based nested uniform (Owen) scramble of a 32-bit fraction v / 2^32:
    each bit is flipped or not according to a hash of the bits above it and the seed
    (the Laine-Karras permutation between two bit reversals), so aligned blocks of
    2^k values map to aligned blocks."""
    v = reverse_bits32(v)
    v ^= (v * 0x3D20ADEA) & MASK32
    v = (v + seed) & MASK32
    v = (v * ((seed >> 16) | 1)) & MASK32
    v ^= (v * 0x05526C56) & MASK32
    v ^= (v * 0x53A22864) & MASK32
    return reverse_bits32(v)


def _sobol_columns() -> list[int]:
    """The generator matrix of the second Sobol dimension, column k for bit k of the
    index, as 32-bit fractions: v_0 = 1/2, v_{k+1} = v_k xor (v_k >> 1)."""
    columns, v = [], 1 << 31
    for _ in range(32):
        columns.append(v)
        v ^= v >> 1
    return columns


def _byte_products(columns: list[int]) -> list[list[int]]:
    """table[b][byte]: the xor of the columns 8b .. 8b + 7 that the bits of `byte` pick,
    so that a matrix-vector product over GF(2) takes four lookups."""
    table = []
    for b in range(4):
        row = []
        for byte in range(256):
            product = 0
            for k in range(8):
                if byte >> k & 1:
                    product ^= columns[8 * b + k]
            row.append(product)
        table.append(row)
    return table


SOBOL_Y_BYTES = _byte_products(_sobol_columns())


def sobol_2d(index: int) -> tuple[int, int]:
    """Point `index` (< 2^32) of the 2D Sobol (0,2)-sequence as two 32-bit fractions:
    the van der Corput sequence (the bits of index mirrored: its generator matrix is
    the reversal) and the second Sobol dimension (_sobol_columns)."""
    t = SOBOL_Y_BYTES
    y = t[0][index & 255] ^ t[1][index >> 8 & 255] ^ t[2][index >> 16 & 255] ^ t[3][index >> 24]
    return reverse_bits32(index), y


def permute_rounds(n: int) -> int:
    """The rounds permute() takes for n elements. Its distance (total variation) from
    a uniformly random permutation shrinks by a factor of about 0.6 per round: below
    0.3% for every n <= 7 with these counts (computed exactly); the rounds a given
    distance needs grow with log n (Hoang, Morris and Rogaway 2012)."""
    return 8 + 2 * (n - 1).bit_length()


def permute(i: int, n: int, p: int) -> int:
    """Element i of a random permutation of range(n) chosen by the 64-bit seed p,
    computed alone: the swap-or-not shuffle (Hoang, Morris and Rogaway, "An
    Enciphering Scheme Based on a Card Shuffle", CRYPTO 2012). Round r pairs each x
    with K - x (mod n) and swaps the pair or not by a random bit of the pair. K and
    the bits come from the round's hash h (splitmix64's stream from state p): K from
    its high 32 bits (scaled to [0, n) by a product, as Lemire's bounded integers),
    the bit of the pair's larger member x from bit x mod 32 of word x // 32 (word 0
    is h's low 32 bits, word w > 0 those of a hash of h + w). Each round is an
    involution, so the result is a
    permutation, and every permutation can come out (a hashed bijection of the next
    power of two, as Kensler's, reaches only 8 of the 24 permutations of 4 elements,
    which pairs the strata of two dimensions by a few fixed patterns)."""
    for r in range(permute_rounds(n)):
        h = mix64((p + (r + 1) * GOLDEN) & MASK64)
        partner = (((h >> 32) * n >> 32) - i) % n
        x = max(i, partner)
        word = h if x < 32 else mix64((h + (x >> 5)) & MASK64)
        if word >> (x & 31) & 1:
            i = partner
    return i


def grid_2d(spp: int) -> tuple[int, int]:
    """(columns, rows) of the stratified sampler's 2D grid: sqrt(spp) each for a square
    spp, else ceil(sqrt(spp)) columns and as many rows as hold spp strata."""
    nx = math.isqrt(spp)
    if nx * nx < spp:
        nx += 1
    return nx, -(-spp // nx)


class Sampler:
    """The uniform numbers of pixel samples (pbrt-v4's interface).

    start_pixel_sample(pixel, index) begins sample `index` of pixel `pixel` (pixel =
    row * image width + column); get_1d() and get_2d() then return its dimensions in
    turn. value_1d(pixel, index, dim) and value_2d(...) are those numbers themselves.
    random() serves the draws of rtpy.sampling (a sampler installed with
    use_generator) as the module docstring says.

    seed      the render's seed
    spp       samples per pixel (the stratified sampler's strata)
    defocus   the camera has a lens: its draws are the LENS dimension
    fallback  the generator of draws past the layout (independent numbers)
    """

    name = ""

    def __init__(
        self,
        seed: int = 0,
        spp: int = 1,
        defocus: bool = False,
        fallback: random.Random | None = None,
    ) -> None:
        if not (isinstance(spp, int) and spp >= 1):
            raise ValueError(f"spp must be a whole number >= 1, got {spp!r}")
        self.seed, self.spp = int(seed), spp
        self.fallback = fallback or random.Random(seed)
        self.layout = tuple(entry for entry in LAYOUT if defocus or entry[0] != LENS)
        self.start_pixel_sample(0, 0)

    def start_pixel_sample(self, pixel: int, index: int) -> None:
        """Begin sample `index` of pixel `pixel`: get_1d() and random() start over."""
        self.pixel, self.index = pixel, index
        self.dimension = 0  # the next dimension get_1d() / get_2d() returns
        self._draws: list[float] = []  # random(): the numbers of its current dimension
        self._next = 0  # random(): the next entry of the layout

    def get_1d(self) -> float:
        self.dimension += 1
        return self.value_1d(self.pixel, self.index, self.dimension - 1)

    def get_2d(self) -> tuple[float, float]:
        self.dimension += 1
        return self.value_2d(self.pixel, self.index, self.dimension - 1)

    def random(self) -> float:
        """The current sample's next draw: its dimensions in LAYOUT order, then
        independent numbers."""
        if not self._draws:
            if self._next >= len(self.layout):
                return self.fallback.random()
            dim, size = self.layout[self._next]
            self._next += 1
            if size == 1:
                return self.value_1d(self.pixel, self.index, dim)
            self._draws = list(self.value_2d(self.pixel, self.index, dim))[::-1]
        return self._draws.pop()

    def value_1d(self, pixel: int, index: int, dim: int) -> float:
        raise NotImplementedError

    def value_2d(self, pixel: int, index: int, dim: int) -> tuple[float, float]:
        raise NotImplementedError


class IndependentSampler(Sampler):
    """Every number its own uniform number (a hash of pixel, index and dimension).
    The renderer's "independent" sampler is the unit's Mersenne Twister itself; this
    class is the same estimator behind the Sampler interface."""

    name = "independent"

    def value_1d(self, pixel: int, index: int, dim: int) -> float:
        return unit_float(hash_key(self.seed, pixel, index, dim, 0))

    def value_2d(self, pixel: int, index: int, dim: int) -> tuple[float, float]:
        return self.value_1d(pixel, index, dim), unit_float(
            hash_key(self.seed, pixel, index, dim, 1)
        )


class StratifiedSampler(Sampler):
    """Jittered strata: sample `index` of a pixel lies in stratum
    permute(index, strata, seed of (pixel, dim)), uniformly inside it."""

    name = "stratified"

    def _stratum(self, pixel: int, index: int, dim: int, strata: int) -> tuple[int, int]:
        """(stratum of the sample, the hash its jitter comes from)."""
        if not 0 <= index < self.spp:
            raise ValueError(f"index must be in [0, spp = {self.spp}), got {index}")
        p = hash_key(self.seed, pixel, dim)
        return permute(index, strata, p), hash_key(self.seed, pixel, index, dim)

    def value_1d(self, pixel: int, index: int, dim: int) -> float:
        k, h = self._stratum(pixel, index, dim, self.spp)
        return jittered(k, unit_float(h), self.spp)

    def value_2d(self, pixel: int, index: int, dim: int) -> tuple[float, float]:
        nx, ny = grid_2d(self.spp)
        k, h = self._stratum(pixel, index, dim, nx * ny)
        row, column = divmod(k, nx)
        return jittered(column, unit_float(h), nx), jittered(row, unit_float(mix64(h)), ny)


class SobolSampler(Sampler):
    """Owen-scrambled 2D Sobol points, padded: per pixel and dimension, its own
    scrambling and its own shuffle of the sample indices (Burley 2020)."""

    name = "sobol"

    def _point(self, pixel: int, index: int, dim: int) -> tuple[int, int, int]:
        """(x, y) of the scrambled, shuffled Sobol point as 32-bit fractions, and the
        hash the scrambling seeds came from."""
        if not 0 <= index <= MASK32:
            raise ValueError(f"index must be in [0, 2^32) (the Sobol points), got {index}")
        h = hash_key(self.seed, pixel, dim)
        shuffled = owen_scramble(index, h & MASK32)
        x, y = sobol_2d(shuffled)
        return x, y, mix64(h)

    def value_1d(self, pixel: int, index: int, dim: int) -> float:
        x, _, h = self._point(pixel, index, dim)
        return owen_scramble(x, h & MASK32) * TWO_TO_MINUS_32

    def value_2d(self, pixel: int, index: int, dim: int) -> tuple[float, float]:
        x, y, h = self._point(pixel, index, dim)
        return (
            owen_scramble(x, h & MASK32) * TWO_TO_MINUS_32,
            owen_scramble(y, h >> 32) * TWO_TO_MINUS_32,
        )


SAMPLERS: dict[str, type[Sampler]] = {
    "independent": IndependentSampler,
    "stratified": StratifiedSampler,
    "sobol": SobolSampler,
}
