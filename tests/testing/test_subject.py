"""Tests for rtpy.testing.subject: the batched questions the checks ask of a material,
how few of them each check asks (every one is a round trip when the material lives
in another process), and LocalMaterial's answers row by row."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from rtpy.materials import Lambertian, Mirror
from rtpy.testing import (
    brdf_between,
    check_energy,
    check_material,
    check_non_negative_finite,
    check_reciprocity,
    check_weights,
    chi2_test,
    light_ray,
    local_hit,
    view_ray,
)
from rtpy.testing.local_setup import NON_NEGATIVE, SAMPLING
from rtpy.testing.pointwise_checks import GRAZING_ANGLES
from rtpy.testing.subject import LocalMaterial, MaterialSubject, as_subject
from rtpy.vec3 import Vec3

from .materials_to_check import DiffuseTransmitter, NonReciprocal, PhongLobe

# A breadth-first quadrature run takes one round per level of refinement; a level
# halves a cell along x or y or both, at most max_depth = 16 times each, so a run
# has at most 2 * 16 + 1 rounds, each one call. chi2_test makes at most 5 runs (all
# bins, the crowded bins, 3 rounds of the largest errors); directional_albedo 2 (all
# strips, the strips its samples disagree with).
ROUNDS_PER_RUN = 2 * 16 + 1


class Counting:
    """A MaterialSubject that counts the calls (and rows) it answers."""

    def __init__(self, material) -> None:
        self.inner = LocalMaterial(material)
        self.is_specular = self.inner.is_specular
        self.calls: Counter[str] = Counter()
        self.rows: Counter[str] = Counter()
        self.tags: list[int] = []

    def draw(self, incident_deg, n, *, seed=0, phi_deg=0.0, inside=False, tag=SAMPLING):
        self.calls["draw"] += 1
        self.rows["draw"] += n
        self.tags.append(tag)
        return self.inner.draw(incident_deg, n, seed=seed, phi_deg=phi_deg, inside=inside, tag=tag)

    def brdf(self, wo, wi, *, inside=False):
        self.calls["brdf"] += 1
        self.rows["brdf"] += len(wo)
        return self.inner.brdf(wo, wi, inside=inside)

    def pdf(self, wo, wi, *, inside=False):
        self.calls["pdf"] += 1
        self.rows["pdf"] += len(wo)
        return self.inner.pdf(wo, wi, inside=inside)


def test_as_subject():
    m = Lambertian()
    s = as_subject(m)
    assert isinstance(s, LocalMaterial) and s.material is m and not s.is_specular
    counting = Counting(m)
    assert isinstance(counting, MaterialSubject) and as_subject(counting) is counting
    assert as_subject(Mirror()).is_specular
    with pytest.raises(TypeError, match="material"):
        as_subject("Lambertian")


def test_local_material_answers_row_by_row():
    m = DiffuseTransmitter()
    rng = np.random.default_rng(3)
    wo = rng.normal(size=(40, 3))
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    wi = rng.normal(size=(40, 3))
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    s = LocalMaterial(m)
    for inside in (False, True):
        f, p = s.brdf(wo, wi, inside=inside), s.pdf(wo, wi, inside=inside)
        assert f.shape == (40, 3) and p.shape == (40,)
        for k in range(40):
            a, b = Vec3(*wo[k]), Vec3(*wi[k])
            assert f[k].tolist() == brdf_between(m, a, b, inside).tolist()
            assert p[k] == m.pdf(view_ray(a), light_ray(b), local_hit(m, inside))
    # The draws are draw_samples' (tag SAMPLING), another stream for another tag.
    a = s.draw(30.0, 50, seed=4)
    b = s.draw(30.0, 50, seed=4, tag=NON_NEGATIVE)
    assert a.n == b.n == 50 and not np.array_equal(a.directions, b.directions)


def test_each_check_asks_the_subject_few_times():
    lobe = Counting(PhongLobe(200.0, kd=0.3, ks=0.7))
    samples = lobe.draw(60.0, 20_000)
    lobe.calls.clear()

    assert check_weights(lobe, 60.0, samples=samples)
    assert lobe.calls == {"brdf": 1, "pdf": 1}  # every sample in one call each
    lobe.calls.clear()

    result = chi2_test(lobe, 60.0, samples=samples)
    assert result.passed()
    assert set(lobe.calls) == {"pdf"} and lobe.calls["pdf"] <= 5 * ROUNDS_PER_RUN
    assert lobe.rows["pdf"] >= 100 * lobe.calls["pdf"]  # batches, not points
    lobe.calls.clear()

    assert check_energy(lobe, 60.0, samples=samples)
    assert set(lobe.calls) == {"brdf"} and lobe.calls["brdf"] <= 2 * ROUNDS_PER_RUN
    lobe.calls.clear()

    glass = Counting(DiffuseTransmitter())
    assert check_reciprocity(glass, n_pairs=300, ior=1.0)  # inside and across: still 2
    assert glass.calls == {"brdf": 2}
    glass.calls.clear()

    assert check_non_negative_finite(glass, n=20, inside=True)
    # The grid of all incident directions in one call each; one draw per direction.
    assert glass.calls == {"brdf": 1, "pdf": 1, "draw": 2 * len(GRAZING_ANGLES)}
    assert set(glass.tags[-2 * len(GRAZING_ANGLES) :]) == {NON_NEGATIVE}


@pytest.mark.slow
def test_check_material_through_a_subject_asks_tens_of_times():
    glass = Counting(DiffuseTransmitter())
    report = check_material(glass, incident_angles=(0.0, 60.0), n_samples=20_000)
    assert report.passed, str(report)
    assert report.material == "Counting"
    # 2 angles x 2 sides: a draw each, and chi2, weights, energy of each.
    assert glass.calls["draw"] == 4 + 2 * 2 * len(GRAZING_ANGLES)
    assert glass.calls["pdf"] <= 4 * (5 * ROUNDS_PER_RUN + 1) + 2
    assert glass.calls["brdf"] <= 4 * (2 * ROUNDS_PER_RUN + 2) + 2 + 2
    print(dict(glass.calls))


def test_a_subject_fails_the_checks_its_material_fails():
    counting = Counting(NonReciprocal())
    result = check_reciprocity(counting, n_pairs=200)
    assert not result and result.detail == check_reciprocity(NonReciprocal(), n_pairs=200).detail
    assert counting.calls == {"brdf": 2}
