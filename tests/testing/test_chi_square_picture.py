"""The picture of a chi-square test (rtpy.testing.chi_square_picture): observed and
expected histograms side by side, their difference coloured by sign, and the polar
plot of BRDF * cos and pdf in the plane of incidence."""

from __future__ import annotations

import numpy as np
from PIL import Image

from rtpy.materials import Lambertian
from rtpy.testing import chi2_test
from rtpy.testing.chi_square_picture import DIVERGING, PANEL, chi2_picture

from .materials_to_check import UniformSampler


def test_the_picture_shows_where_the_samples_disagree_with_the_pdf(tmp_path):
    """UniformSampler draws too many samples near the horizon and too few near the
    normal for its pdf cos / pi: the difference panel is red (too many) in the bottom
    row of the upper hemisphere and blue (too few) in its top row."""
    material = UniformSampler()
    result = chi2_test(material, 30.0, n_samples=20_000, theta_bins=8, phi_bins=8, seed=1)
    assert not result.passed(0.01)
    path = chi2_picture(result, tmp_path / "sub" / "chi2.png", 30.0, subject=material)
    image = np.asarray(Image.open(path).convert("RGB")).astype(int)
    assert path.is_file() and image.shape[1] > 3 * PANEL  # three histograms and the plot
    # the difference panel: the third, from x = 3 margins + 2 panels
    x0 = 3 * 10 + 2 * PANEL
    top = 2 * 18 + 5
    cell = PANEL // 8
    near_normal = image[top + cell // 2, x0 + cell // 2]
    near_horizon = image[top + 3 * cell + cell // 2, x0 + cell // 2]
    blue, red = DIVERGING[0], DIVERGING[-1]
    assert np.abs(near_normal - blue).sum() < np.abs(near_normal - red).sum()
    assert np.abs(near_horizon - red).sum() < np.abs(near_horizon - blue).sum()


def test_the_picture_of_a_correct_material_has_no_strong_colours(tmp_path):
    """A correct Lambertian: the difference is near 0 (white-ish) everywhere, and
    without a subject no polar plot is drawn (three panels only)."""
    result = chi2_test(Lambertian(), 30.0, n_samples=20_000, theta_bins=8, phi_bins=8, seed=1)
    path = chi2_picture(result, tmp_path / "ok.png", 30.0)
    image = np.asarray(Image.open(path).convert("RGB")).astype(int)
    assert image.shape[1] < 4 * PANEL
    x0, top = 3 * 10 + 2 * PANEL, 2 * 18 + 5
    panel = image[top : top + 8 * (PANEL // 8), x0 : x0 + PANEL]
    assert (panel.min(axis=2) > 120).all()  # pale: |z| < about 3 everywhere
