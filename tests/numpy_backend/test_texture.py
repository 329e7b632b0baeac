"""Batched textures (rtpy.numpy_backend.texture) against the scalar Texture.value.

Texture lookups are gathers and floors, so the batched values must equal the scalar
ones exactly, also on checker cell boundaries, at u, v outside [0, 1] and on texel edges.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from rtpy.numpy_backend.hit_info import HitBatch
from rtpy.numpy_backend.texture import SCALAR, TextureTable
from rtpy.texture import CheckerTexture, ImageTexture, SolidColor
from rtpy.vec3 import Color

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def hit_batch(point: np.ndarray, u: np.ndarray, v: np.ndarray) -> HitBatch:
    n = len(u)
    z = np.zeros((n, 3))
    z[:, 2] = 1.0
    x = np.zeros((n, 3))
    x[:, 0] = 1.0
    return HitBatch(point, z, z.copy(), np.ones(n), np.ones(n, bool), u, v, x)


def random_hits(rng: np.random.Generator, n: int, scale: float = 1.0) -> HitBatch:
    """Points on and off checker cell boundaries (multiples of scale), u and v inside,
    outside and on the edges of [0, 1] and on texel edges."""
    point = rng.uniform(-5.0, 5.0, (n, 3))
    on_edge = rng.random((n, 3)) < 0.3
    point[on_edge] = np.round(point[on_edge] / scale) * scale
    u, v = rng.uniform(-0.2, 1.2, n), rng.uniform(-0.2, 1.2, n)
    special = np.array([0.0, 1.0, -0.0, 0.5, 0.25, 1.0 - 1e-17, 1e-300, 3.0, -3.0])
    k = rng.random(n) < 0.3
    u[k] = rng.choice(special, k.sum())
    k = rng.random(n) < 0.3
    v[k] = rng.choice(special, k.sum())
    return hit_batch(point, u, v)


def scalar_values(textures, ids, hits: HitBatch) -> np.ndarray:
    return np.array([tuple(textures[t].value(hits.hit_info(i))) for i, t in enumerate(ids)])


colors = st.tuples(*[st.floats(0.0, 1.0)] * 3).map(lambda c: Color(*c))


@st.composite
def textures(draw) -> list:
    out = []
    for _ in range(draw(st.integers(1, 6))):
        kind = draw(st.sampled_from(["solid", "checker", "image"]))
        if kind == "solid":
            out.append(SolidColor(draw(colors)))
        elif kind == "checker":
            scale = draw(st.sampled_from([0.1, 0.5, 1.0, 3.0, 1e-3]))
            out.append(CheckerTexture(scale, draw(colors), draw(colors)))
        else:
            h, w = draw(st.integers(1, 7)), draw(st.integers(1, 7))
            seed = draw(st.integers(0, 2**32 - 1))
            out.append(ImageTexture(np.random.default_rng(seed).random((h, w, 3))))
    return out


@given(textures(), st.integers(0, 2**32 - 1))
def test_table_equals_scalar_values(texs, seed):
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 300, scale=getattr(texs[0], "inv_scale", 1.0) ** -1)
    ids = rng.integers(len(texs), size=300)
    np.testing.assert_array_equal(
        TextureTable(texs).value(ids, hits), scalar_values(texs, ids, hits)
    )


def test_checker_cells_on_boundaries_and_negative_coordinates():
    tex = CheckerTexture(0.5, Color(1.0, 0.0, 0.0), Color(0.0, 0.0, 1.0))
    g = np.arange(-4, 5) * 0.5
    point = np.stack(np.meshgrid(g, g, g), axis=-1).reshape(-1, 3)
    point = np.concatenate([point, point + 1e-12, point - 1e-12, point * (1 + 1e-16)])
    n = len(point)
    hits = hit_batch(point, np.zeros(n), np.zeros(n))
    ids = np.zeros(n, dtype=int)
    value = TextureTable([tex]).value(ids, hits)
    np.testing.assert_array_equal(value, scalar_values([tex], ids, hits))
    assert 0.3 < value[:, 0].mean() < 0.7  # both colours occur


def test_image_nearest_texel_edges_and_clamping():
    rng = np.random.default_rng(3)
    tex = ImageTexture(rng.random((4, 5, 3)))
    edges_u = np.arange(6) / 5
    edges_v = np.arange(5) / 4
    u = np.concatenate([edges_u, np.nextafter(edges_u, -1), np.nextafter(edges_u, 2), [-1, 2]])
    v = np.concatenate([edges_v, np.nextafter(edges_v, -1), np.nextafter(edges_v, 2), [-1, 2]])
    uu, vv = (a.ravel() for a in np.meshgrid(u, v))
    hits = hit_batch(np.zeros((len(uu), 3)), uu, vv)
    ids = np.zeros(len(uu), dtype=int)
    np.testing.assert_array_equal(
        TextureTable([tex]).value(ids, hits), scalar_values([tex], ids, hits)
    )
    # v = 0 is the bottom row, u = 0 the left column
    corner = hit_batch(np.zeros((1, 3)), np.zeros(1), np.zeros(1))
    np.testing.assert_array_equal(TextureTable([tex]).value([0], corner)[0], tex.pixels[3, 0])


def test_image_from_file_and_shared_pixels_stored_once():
    tex = ImageTexture.from_file(SCENES / "planet.png")
    other = ImageTexture(np.random.default_rng(0).random((3, 2, 3)))
    table = TextureTable([tex, other, tex, SolidColor(Color(0.1, 0.2, 0.3))])
    assert len(table.atlas) == tex.width * tex.height + 6
    rng = np.random.default_rng(1)
    hits = random_hits(rng, 500)
    ids = rng.integers(4, size=500)
    np.testing.assert_array_equal(table.value(ids, hits), scalar_values(table.textures, ids, hits))


def test_rows_select_hits():
    rng = np.random.default_rng(2)
    texs = [
        CheckerTexture(0.7, Color(1, 1, 1), Color(0, 0, 0)),
        ImageTexture(rng.random((5, 5, 3))),
    ]
    hits = random_hits(rng, 50)
    rows = np.array([3, 7, 7, 20, 49])
    ids = np.array([0, 1, 0, 1, 1])
    expected = scalar_values(texs, ids, hits.take(rows))
    np.testing.assert_array_equal(TextureTable(texs).value(ids, hits, rows), expected)


class Stripes(SolidColor):
    """A student's texture: a subclass, so it must not be read as a SolidColor."""

    def value(self, hit):
        return self.color if hit.u < 0.5 else Color(hit.v, hit.point.e0, 0.25)


def test_unknown_texture_class_uses_its_scalar_value():
    texs = [Stripes(Color(0.3, 0.6, 0.9)), SolidColor(Color(0.2, 0.2, 0.2))]
    table = TextureTable(texs)
    assert table.kind[0] == SCALAR
    rng = np.random.default_rng(4)
    hits = random_hits(rng, 100)
    ids = rng.integers(2, size=100)
    np.testing.assert_array_equal(table.value(ids, hits), scalar_values(texs, ids, hits))


def test_solid_only_table_is_a_gather():
    texs = [SolidColor(Color(i / 500, 0.5, 1 - i / 500)) for i in range(500)]
    table = TextureTable(texs)
    ids = np.arange(500)[::-1]
    hits = hit_batch(np.full((500, 3), np.nan), np.full(500, np.nan), np.full(500, np.nan))
    np.testing.assert_array_equal(table.value(ids, hits), table.color[ids])  # reads no hit data
