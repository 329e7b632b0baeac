"""Samplers for arrays of pixel samples: the twin of rtpy/sampler.py.

value_1d(pixel, index, dim) and value_2d(...) of each sampler take arrays of pixels
and sample indices and return, element by element, the numbers rtpy.sampler's
sampler of the same name returns (the same integer hashes, in 64- and 32-bit
unsigned arithmetic that wraps as the scalar code's masks do).

LaneSampler is what the backend's kernels draw from: a numpy-Generator-like object
whose random(size) returns, for the lanes (camera samples) it is told about, the
next dimension of each lane's sample. It serves the camera's draws (pixel, lens) and
the first hit's draws when the call covers all the lanes; a call for part of the
lanes (a kernel that handles some of the hits) and every later draw get independent
numbers of the unit's Generator, so every estimate stays unbiased.
"""

from __future__ import annotations

import numpy as np

from ..sampler import (
    GOLDEN,
    LIGHT_CHOICE,
    MASK64,
    ONE_MINUS_EPSILON,
    PIXEL,
    SAMPLERS,
    SOBOL_Y_BYTES,
    TWO_TO_MINUS_32,
    TWO_TO_MINUS_53,
    grid_2d,
    permute_rounds,
)

U64, U32 = np.uint64, np.uint32
MASK32 = U64(0xFFFFFFFF)
_SOBOL_Y_BYTES = np.array(SOBOL_Y_BYTES, dtype=U32)


def mix64(z: np.ndarray) -> np.ndarray:
    """rtpy.sampler.mix64 of uint64 arrays (products wrap modulo 2^64)."""
    with np.errstate(over="ignore"):
        z = z + U64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> U64(30))) * U64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> U64(27))) * U64(0x94D049BB133111EB)
    return z ^ (z >> U64(31))


def hash_key(*key) -> np.ndarray:
    """rtpy.sampler.hash_key of integers and integer arrays (broadcast together)."""
    h = U64(0)
    for k in key:
        h = mix64(h ^ np.asarray(k).astype(U64))
    return np.asarray(h, dtype=U64)


def unit_float(h: np.ndarray) -> np.ndarray:
    return (h >> U64(11)).astype(np.float64) * TWO_TO_MINUS_53


def jittered(k: np.ndarray, u: np.ndarray, n: int) -> np.ndarray:
    return np.minimum((k + u) / n, ONE_MINUS_EPSILON)


def reverse_bits32(v: np.ndarray) -> np.ndarray:
    """The 32 bits of each uint32 in reverse order."""
    v = v.astype(U32)
    v = ((v >> U32(1)) & U32(0x55555555)) | ((v & U32(0x55555555)) << U32(1))
    v = ((v >> U32(2)) & U32(0x33333333)) | ((v & U32(0x33333333)) << U32(2))
    v = ((v >> U32(4)) & U32(0x0F0F0F0F)) | ((v & U32(0x0F0F0F0F)) << U32(4))
    v = ((v >> U32(8)) & U32(0x00FF00FF)) | ((v & U32(0x00FF00FF)) << U32(8))
    return (v >> U32(16)) | (v << U32(16))


def owen_scramble(v: np.ndarray, seed: np.ndarray) -> np.ndarray:
    """rtpy.sampler.owen_scramble of uint32 arrays."""
    seed = seed.astype(U32)
    v = reverse_bits32(v)
    v ^= v * U32(0x3D20ADEA)
    v += seed
    v *= (seed >> U32(16)) | U32(1)
    v ^= v * U32(0x05526C56)
    v ^= v * U32(0x53A22864)
    return reverse_bits32(v)


def sobol_2d(index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rtpy.sampler.sobol_2d of a uint32 array."""
    index = index.astype(U32)
    y = _SOBOL_Y_BYTES[0].take(index & U32(255))
    for b in (1, 2, 3):
        y ^= _SOBOL_Y_BYTES[b].take((index >> U32(8 * b)) & U32(255))
    return reverse_bits32(index), y


def low32(h: np.ndarray) -> np.ndarray:
    """The low 32 bits of uint64 values, as uint32."""
    return (h & MASK32).astype(np.uint32)


def permute(i: np.ndarray, n: int, p: np.ndarray) -> np.ndarray:
    """rtpy.sampler.permute of arrays i (int) and p (uint64), broadcast together. A
    round's hashes depend on p alone, which repeats along the samples of a pixel: they
    are made once per run of equal p (K and a table of the words of each run) and
    gathered per element, where the arithmetic is in uint32 (n <= 2^31): K - x (mod n)
    as the smaller of K + n - x and that minus n (which wraps to a huge number when it
    would be negative)."""
    i, p = np.broadcast_arrays(np.asarray(i), np.asarray(p).astype(U64))
    shape, i, p = i.shape, i.ravel().astype(np.uint32), p.ravel()
    changes = np.ones(p.size, dtype=bool)
    np.not_equal(p[1:], p[:-1], out=changes[1:])
    starts = np.flatnonzero(changes)
    run = np.repeat(np.arange(starts.size), np.diff(starts, append=p.size))  # of equal p
    p = p.take(starts)
    words = max(1, (n + 31) >> 5)  # 32-bit words: a bit for each pair's larger member
    first = run * words  # each element's row in the table of words
    n32 = np.uint32(n)
    with np.errstate(over="ignore"):
        for r in range(permute_rounds(n)):
            h = mix64(p + U64((r + 1) * GOLDEN & MASK64))
            k = (h >> U64(32)) * U64(n) >> U64(32)
            d = k.astype(np.uint32).take(run) + n32 - i
            partner = np.minimum(d, d - n32)
            x = np.maximum(i, partner)
            if words == 1:
                word = low32(h).take(run)
            elif p.size * words <= i.size:  # a table of every run's words, gathered
                table = np.stack([h] + [mix64(h + U64(w)) for w in range(1, words)], axis=1)
                word = low32(table).ravel().take(first + (x >> np.uint32(5)))
            else:  # runs too short for a table: each element's own word
                h, w = h.take(run), (x >> np.uint32(5)).astype(U64)
                word = low32(np.where(w == U64(0), h, mix64(h + w)))
            swap = (word >> (x & np.uint32(31))) & np.uint32(1)
            i ^= (i ^ partner) & (np.uint32(0) - swap)  # partner where swap is 1
    return i.astype(np.int64).reshape(shape)


class Sampler:
    """rtpy.sampler.Sampler's values for arrays of pixels and sample indices."""

    name = ""

    def __init__(self, seed: int = 0, spp: int = 1) -> None:
        self.seed, self.spp = int(seed), int(spp)

    def value_1d(self, pixel: np.ndarray, index: np.ndarray, dim: int) -> np.ndarray:
        raise NotImplementedError

    def value_2d(self, pixel: np.ndarray, index: np.ndarray, dim: int) -> np.ndarray:
        """An array (2, N): the x and y of each sample's point."""
        raise NotImplementedError


class IndependentSampler(Sampler):
    name = "independent"

    def value_1d(self, pixel, index, dim):
        return unit_float(hash_key(self.seed, pixel, index, dim, 0))

    def value_2d(self, pixel, index, dim):
        return np.stack(
            [
                self.value_1d(pixel, index, dim),
                unit_float(hash_key(self.seed, pixel, index, dim, 1)),
            ]
        )


class StratifiedSampler(Sampler):
    name = "stratified"

    def _stratum(self, pixel, index, dim, strata):
        index = np.asarray(index)
        if index.size and not (0 <= index.min() and index.max() < self.spp):
            raise ValueError(f"index must be in [0, spp = {self.spp})")
        p = hash_key(self.seed, pixel, dim)
        return permute(index, strata, p), hash_key(self.seed, pixel, index, dim)

    def value_1d(self, pixel, index, dim):
        k, h = self._stratum(pixel, index, dim, self.spp)
        return jittered(k, unit_float(h), self.spp)

    def value_2d(self, pixel, index, dim):
        nx, ny = grid_2d(self.spp)
        k, h = self._stratum(pixel, index, dim, nx * ny)
        row, column = np.divmod(k, nx)
        return np.stack(
            [jittered(column, unit_float(h), nx), jittered(row, unit_float(mix64(h)), ny)]
        )


class SobolSampler(Sampler):
    name = "sobol"

    def _point(self, pixel, index, dim):
        index = np.asarray(index)
        if index.size and not (0 <= index.min() and index.max() <= 0xFFFFFFFF):
            raise ValueError("index must be in [0, 2^32) (the Sobol points)")
        h = hash_key(self.seed, pixel, dim)
        shuffled = owen_scramble(index.astype(U64), h & MASK32)
        x, y = sobol_2d(shuffled)
        return x, y, mix64(h)

    def value_1d(self, pixel, index, dim):
        x, _, h = self._point(pixel, index, dim)
        return owen_scramble(x, h & MASK32).astype(np.float64) * TWO_TO_MINUS_32

    def value_2d(self, pixel, index, dim):
        x, y, h = self._point(pixel, index, dim)
        return np.stack(
            [
                owen_scramble(x, h & MASK32).astype(np.float64) * TWO_TO_MINUS_32,
                owen_scramble(y, h >> U64(32)).astype(np.float64) * TWO_TO_MINUS_32,
            ]
        )


BATCH_SAMPLERS: dict[str, type[Sampler]] = {
    "independent": IndependentSampler,
    "stratified": StratifiedSampler,
    "sobol": SobolSampler,
}
assert BATCH_SAMPLERS.keys() == SAMPLERS.keys()


class LaneSampler:
    """A numpy Generator for the kernels that draws the sampler's dimensions.

    pixel, index  the pixel (row * width + column) and sample index of each lane
    generator     the unit's Generator: every draw the sampler does not serve
    lanes         the lanes a full call covers (None: every draw is independent)
    dim           the dimension the next served draw takes

    random(size) with size n or (k, n) and n = len(lanes) returns the lanes' next
    dimensions: k = 1 one 1D dimension, k = 2 one 2D dimension, k = 3 a 1D then a 2D
    one. Every other method and call is the Generator's.
    """

    def __init__(self, sampler: Sampler, pixel, index, generator, lanes=None, dim=PIXEL):
        self.sampler, self.pixel, self.index = sampler, pixel, index
        self.generator, self.lanes, self.dim = generator, lanes, dim

    def camera(self) -> LaneSampler:
        """The sampler of the camera's draws (pixel, then lens): every lane."""
        return LaneSampler(self.sampler, self.pixel, self.index, self.generator, slice(None))

    def first_hit(self, lanes: np.ndarray) -> LaneSampler:
        """The sampler of the first hit's draws for the lanes (camera samples) `lanes`."""
        return LaneSampler(
            self.sampler, self.pixel, self.index, self.generator, lanes, LIGHT_CHOICE
        )

    def random(self, size=None):
        shape = (size,) if isinstance(size, int) else tuple(size or ())
        if self.lanes is None:
            return self.generator.random(size)
        n = len(self.pixel) if isinstance(self.lanes, slice) else len(self.lanes)
        if not shape or shape[-1] != n or len(shape) > 2 or n == 0:
            return self.generator.random(size)
        pixel, index = self.pixel[self.lanes], self.index[self.lanes]
        rows = 1 if len(shape) == 1 else shape[0]
        if rows > 3:
            return self.generator.random(size)
        parts = []
        if rows % 2:
            parts.append(self.sampler.value_1d(pixel, index, self.dim)[None])
            self.dim += 1
        if rows >= 2:
            parts.append(self.sampler.value_2d(pixel, index, self.dim))
            self.dim += 1
        values = np.concatenate(parts)
        return values[0] if len(shape) == 1 else values

    def __getattr__(self, name):
        return getattr(self.generator, name)


def first_hit_generator(rng, lanes: np.ndarray, segment: int):
    """What the path integrator's kernels draw from at segment `segment` for the
    live lanes `lanes`: a LaneSampler's first-hit draws, else the plain generator."""
    if not isinstance(rng, LaneSampler):
        return rng
    return rng.first_hit(lanes) if segment == 1 else rng.generator
