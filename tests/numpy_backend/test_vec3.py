"""rtpy.numpy_backend.vec3: n vectors as three columns, against rtpy.vec3 bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy import vec3 as scalar
from rtpy.numpy_backend import vec3

from .geometry_checks import V, arr, unit, vec

unit_vec = vec.filter(lambda v: np.linalg.norm(v) > 1e-3).map(unit)


def columns(vectors) -> vec3.Columns:
    return vec3.components(np.array(vectors, dtype=np.float64).reshape(-1, 3))


@settings(max_examples=100)
@given(st.lists(st.tuples(vec, unit_vec, st.floats(0.3, 3.0)), min_size=1, max_size=8))
def test_dot_reflect_and_refract_are_the_scalar_functions(cases):
    v, n = columns([c[0] for c in cases]), columns([c[1] for c in cases])
    eta = np.array([c[2] for c in cases])
    uv = columns([unit(c[0]) if np.linalg.norm(c[0]) > 1e-3 else (0, 0, -1) for c in cases])
    dots, reflected, refracted = vec3.dot(v, n), vec3.reflect(v, n), vec3.refract(uv, n, eta)
    for k, (a, normal, e) in enumerate(cases):
        u = V(vec3.stack(*uv)[k])
        assert dots[k] == scalar.dot(V(a), V(normal))
        np.testing.assert_array_equal(
            vec3.stack(*reflected)[k], arr(scalar.reflect(V(a), V(normal)))
        )
        np.testing.assert_array_equal(
            vec3.stack(*refracted)[k], arr(scalar.refract(u, V(normal), e))
        )


@given(st.lists(vec, max_size=6))
def test_conversions_to_and_from_vec3_and_columns(points):
    rows = vec3.rows_of(V(p) for p in points)
    assert rows.shape == (len(points), 3) and rows.dtype == np.float64
    np.testing.assert_array_equal(vec3.stack(*vec3.components(rows)), rows)
    for k, p in enumerate(points):
        np.testing.assert_array_equal(vec3.row(V(p)), rows[k])
        back = vec3.to_vec3(rows[k])
        assert back == V(p) and type(back.e0) is float
    picked = vec3.take(vec3.components(rows), slice(None, None, 2))
    np.testing.assert_array_equal(vec3.stack(*picked), rows[::2])
