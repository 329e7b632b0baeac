"""Tests for rtpy.engine.display: the display transform (gamma or sRGB) to 8-bit values."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy.engine.display import linear_to_srgb, png_info, to_8bit
from rtpy.texture import srgb_to_linear

from ..io.test_image import rgb

# --------------------------------------------------------------------------- to_8bit


# NaN -> uint8 casts are platform-dependent (and warn): NaN must be handled explicitly.
@pytest.mark.filterwarnings("error")
def test_to_8bit_endpoints_and_clamping() -> None:
    out = to_8bit(rgb([0.0, 1.0, 1.5, 1e9, np.inf, -0.2, -np.inf, np.nan]), gamma=2.0)
    assert out.dtype == np.uint8
    assert out.shape == (1, 8, 3)
    assert out[0, :, 0].tolist() == [0, 255, 255, 255, 255, 0, 0, 0]
    # All three channels are treated the same.
    assert np.array_equal(out[..., 0], out[..., 1])
    assert np.array_equal(out[..., 0], out[..., 2])


# NaN -> uint8 casts are platform-dependent (and warn): NaN must be handled explicitly.
@pytest.mark.filterwarnings("error")
def test_to_8bit_nan_is_zero_per_channel() -> None:
    img = np.array([[[np.nan, 1.0, 0.25]]])
    assert to_8bit(img, 1.0).tolist() == [[[0, 255, 64]]]


def test_to_8bit_gamma_2() -> None:
    # 0.25 ** (1/2) = 0.5 -> 127.5 -> rounds to 128 (round(255 * 0.5) == 128).
    assert to_8bit(rgb([0.25]), 2.0)[0, 0, 0] == 128
    # 0.5 ** (1/2) = 0.7071 -> 180.3 -> 180.
    assert to_8bit(rgb([0.5]), 2.0)[0, 0, 0] == 180


def test_to_8bit_gamma_2_2() -> None:
    # 0.5 ** (1/2.2) = 0.7297 -> 186.08 -> 186; gamma encoding brightens mid-tones.
    assert to_8bit(rgb([0.5]), 2.2)[0, 0, 0] == 186


def test_to_8bit_gamma_1_is_linear() -> None:
    values = [0.0, 0.1, 0.2, 0.5, 0.75, 1.0]
    out = to_8bit(rgb(values), 1.0)[0, :, 0].tolist()
    assert out == [0, 26, 51, 128, 191, 255]
    # No encoding: output / 255 equals the input to within half a step.
    assert np.all(np.abs(np.array(out) / 255.0 - np.array(values)) <= 0.5 / 255.0)


def test_to_8bit_does_not_modify_input() -> None:
    img = np.array([[[np.nan, 2.0, -1.0]]])
    to_8bit(img, 2.0)
    assert np.isnan(img[0, 0, 0]) and img[0, 0, 1] == 2.0 and img[0, 0, 2] == -1.0


@pytest.mark.parametrize("gamma", [0.0, -1.0, float("nan"), float("inf")])
def test_to_8bit_rejects_bad_gamma(gamma: float) -> None:
    with pytest.raises(ValueError, match="gamma"):
        to_8bit(rgb([0.5]), gamma)


@pytest.mark.parametrize("shape", [(4, 4), (4, 4, 4), (4, 4, 1), (3,)])
def test_to_8bit_rejects_bad_shape(shape: tuple[int, ...]) -> None:
    with pytest.raises(ValueError, match="shape"):
        to_8bit(np.zeros(shape), 2.0)


finite_or_inf = st.floats(allow_nan=False, min_value=-1e300, max_value=1e300) | st.sampled_from(
    [float("inf"), float("-inf")]
)


@given(a=finite_or_inf, b=finite_or_inf, gamma=st.floats(min_value=0.2, max_value=5.0))
def test_to_8bit_monotone(a: float, b: float, gamma: float) -> None:
    lo, hi = min(a, b), max(a, b)
    out = to_8bit(rgb([lo, hi]), gamma)[0, :, 0]
    assert int(out[0]) <= int(out[1])


@given(x=st.floats(min_value=0.0, max_value=1.0), gamma=st.floats(min_value=0.2, max_value=5.0))
def test_to_8bit_matches_formula(x: float, gamma: float) -> None:
    expected = np.floor(255.0 * x ** (1.0 / gamma) + 0.5)
    assert to_8bit(rgb([x]), gamma)[0, 0, 0] == expected


def test_srgb_curve_values_and_inverse() -> None:
    # IEC 61966-2-1: linear toe below 0.0031308, 1.055 x^(1/2.4) - 0.055 above; the
    # two pieces meet there, and the curve undoes the texture decoder's.
    x = np.array([0.0, 0.001, 0.0031308, 0.18, 0.5, 1.0])
    y = linear_to_srgb(x)
    assert y[1] == pytest.approx(0.01292)
    assert 12.92 * 0.0031308 == pytest.approx(1.055 * 0.0031308 ** (1 / 2.4) - 0.055, abs=1e-6)
    assert y[-1] == pytest.approx(1.0)
    np.testing.assert_allclose(srgb_to_linear(y), x, rtol=1e-12, atol=1e-15)


def test_to_8bit_srgb() -> None:
    # 0.5 -> 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 188; gamma 2 gives 180 there.
    assert to_8bit(rgb([0.0, 0.5, 1.0]), "srgb")[0, :, 0].tolist() == [0, 188, 255]
    assert to_8bit(rgb([0.5]), 2.0)[0, 0, 0] == 180


@pytest.mark.parametrize("gamma", ["linear", "SRGB", True])
def test_to_8bit_refuses_other_transforms(gamma) -> None:
    with pytest.raises((TypeError, ValueError), match="gamma"):
        to_8bit(rgb([0.5]), gamma)


@pytest.mark.parametrize("gamma", [1e-5, 5e-324, 4e-5, 2.2, 1.0, 2e5, 1e300, "srgb"])
def test_every_gamma_in_range_has_png_chunks_pillow_writes(tmp_path, gamma) -> None:
    """The gAMA chunk holds 100000 / gamma when that is a PNG integer (1 to 2^31 - 1);
    a gamma beyond, as tiny as 5e-324 or as large as 1e300, writes no gAMA chunk
    rather than failing (struct.error, OverflowError) after the render."""
    from PIL import Image

    path = tmp_path / "x.png"
    Image.new("RGB", (2, 2)).save(path, pnginfo=png_info(gamma))
    with Image.open(path) as im:
        chunks = im.info
    if gamma == "srgb":
        assert "srgb" in chunks and "gamma" not in chunks
        return
    recorded = 100000.0 / gamma
    if 1 <= recorded <= 2**31 - 1:
        assert chunks["gamma"] == pytest.approx(round(recorded) / 100000.0)
    else:
        assert "gamma" not in chunks
