# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 07 hidden checks: only the autograder holds them (assignments/week07/hidden/
never ships to students). Their inputs come from grading_seed, new for every
submission, so code that is right only for the graders' fixed inputs fails them.

False failures: (u, v) and checker cells are compared with their formulas at points
kept away from the seams and cell borders (by 1e-6 in u, v or cell coordinate, a
million times the rounding): a correct solution never fails them.
"""

import math

import numpy as np

from rtpy.grading import points
from rtpy.grading.autograder_seed import grading_rng

MARGIN = 1e-6


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


@points(2)
def test_sphere_and_quad_uv_at_new_points(probe):
    """Sphere.surface_uv and Quad.surface_uv at new points"""
    rng = grading_rng(701)
    spheres, asked = [], []
    for _ in range(100):
        u, v = rng.uniform(MARGIN, 1 - MARGIN, 2)
        phi, theta = 2 * math.pi * u, math.pi * v
        # phi from -x around +y, theta from -y: the inverse of RTIOW's (u, v)
        n = np.array(
            [-math.cos(phi) * math.sin(theta), -math.cos(theta), math.sin(phi) * math.sin(theta)]
        )
        center, radius = rng.uniform(-5, 5, 3), float(rng.uniform(0.2, 3))
        spheres.append((u, v, center, radius, n))
        asked.append(
            {"center": center, "radius": radius, "point": center + radius * n, "normal": n}
        )
    for (u, v, center, radius, n), got in zip(
        spheres, probe.week07_sphere_surface_uv(cases=asked), strict=True
    ):
        assert np.allclose(got, (u, v), atol=1e-9), (
            f"Sphere.surface_uv (rtpy/sphere.py) at the point {(center + radius * n).round(4)} of "
            f"the sphere at {center.round(3)}, radius {radius:.3f}: {np.round(got, 6)}, expected "
            f"({u:.6f}, {v:.6f}): u = phi / (2 pi) with phi = atan2(-z, x) + pi, v = theta / pi "
            "with theta = acos(-y), from the unit outward normal"
        )
    quads, asked = [], []
    for _ in range(50):
        q, a, b = rng.uniform(-3, 3, 3), rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        if np.linalg.norm(np.cross(a, b)) < 0.3 * np.linalg.norm(a) * np.linalg.norm(b):
            continue
        alpha, beta = rng.uniform(0, 1, 2)
        point = q + alpha * a + beta * b
        normal = unit(np.cross(a, b))
        quads.append((alpha, beta))
        asked.append({"q": q, "u": a, "v": b, "ray": [point + normal, -normal], "t": 1.0})
    for (alpha, beta), got in zip(quads, probe.week07_quad_surface_uv(cases=asked), strict=True):
        assert np.allclose(got, (alpha, beta), atol=1e-9), (
            f"Quad.surface_uv (rtpy/quad.py) at q + {alpha:.4f} u + {beta:.4f} v: {np.round(got, 6)}, "
            "expected (alpha, beta), the point's coordinates along u and v"
        )


@points(2)
def test_checker_at_new_points(probe):
    """CheckerTexture.value: 3-D cells at new points and scales"""
    rng = grading_rng(702)
    even, odd = [0.9, 0.8, 0.7], [0.1, 0.2, 0.3]
    cases, asked = [], []
    for _ in range(200):
        scale = float(rng.uniform(0.2, 3))
        cells = rng.integers(-20, 20, 3) + rng.uniform(MARGIN, 1 - MARGIN, 3)
        point = cells * scale
        cases.append((scale, cells, point))
        asked.append({"scale": scale, "even": even, "odd": odd, "point": point})
    for (scale, cells, point), got in zip(
        cases, probe.week07_checker_value(cases=asked), strict=True
    ):
        want = even if int(np.floor(cells).sum()) % 2 == 0 else odd
        assert np.allclose(got, want), (
            f"CheckerTexture.value (rtpy/texture.py), scale {scale:.4f}, at {point.round(4)}: "
            f"{got.round(4)}, expected {want}: the cell is floor(x / scale) + floor(y / scale) + "
            "floor(z / scale), even cells get `even`"
        )
