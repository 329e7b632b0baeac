"""Generate scenes/planet.png: an invented planet for the week-7 texture scene (128 x 64 PNG).

The image is equirectangular and laid out for rtpy's sphere (u, v), which follow RTIOW:
u = phi / (2 pi) with phi = atan2(-z, x) + pi, v = theta / pi with theta = acos(-y), and
v = 0 is the image's bottom row. Every pixel is turned back into its point on the unit sphere,
and the terrain height is a smooth noise evaluated at that 3-D point (a sum of random plane
waves), so the map wraps seamlessly around the sphere and has no seam or pinch at the poles.
Low ground is ocean (deep to shallow blue), high ground is land (green lowlands, brown
highlands), and the polar caps are white.

The wave parameters come from random.Random(SEED), so re-running the script writes the same
image. Run ``python scripts/make_planet_texture.py``.
"""

import math
import random
from pathlib import Path

import numpy as np
from PIL import Image

SCENES = Path(__file__).resolve().parent.parent / "scenes"
OUT_NAME = "planet.png"
WIDTH, HEIGHT = 128, 64
SEED = 3
N_WAVES = 64
SEA_LEVEL = 0.08  # in units of the noise's standard deviation; ~47% land

OCEAN_DEEP = np.array([12, 36, 104], dtype=np.float64)
OCEAN_SHALLOW = np.array([38, 110, 178], dtype=np.float64)
LAND_LOW = np.array([58, 128, 52], dtype=np.float64)
LAND_HIGH = np.array([124, 96, 58], dtype=np.float64)
ICE = np.array([240, 244, 248], dtype=np.float64)


def sphere_points(width: int, height: int) -> np.ndarray:
    """Unit-sphere point of each pixel's center, shape (height, width, 3); row 0 is the top."""
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    phi = 2.0 * math.pi * u[np.newaxis, :]
    theta = math.pi * v[:, np.newaxis]
    # Inverse of RTIOW's get_sphere_uv: y = -cos(theta), x = -cos(phi) sin(theta),
    # z = sin(phi) sin(theta).
    sin_t = np.sin(theta)
    x = -np.cos(phi) * sin_t
    y = np.broadcast_to(-np.cos(theta), (height, width))
    z = np.sin(phi) * sin_t
    return np.stack([x, y, z], axis=-1)


def noise(points: np.ndarray, rng: random.Random) -> np.ndarray:
    """Smooth random field on the sphere, normalised to mean 0 and standard deviation 1."""
    total = np.zeros(points.shape[:-1])
    for _ in range(N_WAVES):
        # Uniform random direction, frequency between 2 and 10, amplitude falling as 1/f.
        zc = 2.0 * rng.random() - 1.0
        az = 2.0 * math.pi * rng.random()
        r = math.sqrt(1.0 - zc * zc)
        direction = np.array([r * math.cos(az), r * math.sin(az), zc])
        freq = 2.0 + 8.0 * rng.random()
        phase = 2.0 * math.pi * rng.random()
        total += np.sin(freq * (points @ direction) + phase) / freq
    return (total - total.mean()) / total.std()


def colorize(height_map: np.ndarray, points: np.ndarray, detail: np.ndarray) -> np.ndarray:
    """RGB (0..255 floats) of each pixel from its height, latitude and a little extra noise."""
    h = height_map[..., np.newaxis]
    sea = np.clip((h + 2.0) / (2.0 + SEA_LEVEL), 0.0, 1.0)
    ocean = OCEAN_DEEP + (OCEAN_SHALLOW - OCEAN_DEEP) * sea**2
    land_t = np.clip((h - SEA_LEVEL) / 2.0, 0.0, 1.0) ** 1.5
    land = LAND_LOW + (LAND_HIGH - LAND_LOW) * land_t
    rgb = np.where(h > SEA_LEVEL, land, ocean)
    # Polar caps: above about 70 degrees of latitude, with a ragged edge.
    latitude = np.degrees(np.arcsin(np.abs(points[..., 1])))
    ice = np.clip((latitude + 4.0 * detail - 70.0) / 2.0, 0.0, 1.0)[..., np.newaxis]
    return rgb + (ICE - rgb) * ice


def make_image() -> Image.Image:
    rng = random.Random(SEED)
    points = sphere_points(WIDTH, HEIGHT)
    height_map = noise(points, rng)
    detail = noise(points * 3.0, rng)
    rgb = colorize(height_map, points, detail)
    pixels = np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
    return Image.fromarray(pixels)


def main() -> None:
    image = make_image()
    SCENES.mkdir(exist_ok=True)
    path = SCENES / OUT_NAME
    # No metadata, fixed compression: the bytes depend only on the pixels.
    image.save(path, format="PNG", optimize=False, compress_level=9)
    print(f"wrote {path} ({image.width}x{image.height})")


if __name__ == "__main__":
    main()
