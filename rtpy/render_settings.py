"""RenderSettings: the [render] table of a scene file."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

INTEGRATOR_NAMES = ("center", "jittered", "direct", "whitted", "path")


@dataclass(frozen=True)
class RenderSettings:
    """How to render. Defaults are the scene format's.

    integrator        "center", "jittered", "direct", "whitted" or "path"
    spp               camera samples per pixel ("center" uses 1)
    max_depth         most ray segments in one path, the camera ray included
    nee               "path" only: sample lights directly and combine with BRDF
                      sampling by MIS; False = BRDF sampling alone
    russian_roulette  segment index after which paths may end at random; 0 = off
    seed              random seed
    gamma             display gamma for 8-bit output
    mis               "path" and "direct", with nee: True = light and BRDF sampling
                      combined by MIS; False = next-event estimation alone (lights
                      found only by light sampling; emission that a BRDF-sampled ray
                      finds after a non-specular bounce is not added)
    """

    integrator: str = "path"
    spp: int = 16
    max_depth: int = 8
    nee: bool = True
    russian_roulette: int = 5
    seed: int = 0
    gamma: float = 2.0
    mis: bool = True

    def __post_init__(self) -> None:
        if self.integrator not in INTEGRATOR_NAMES:
            raise ValueError(
                f"integrator must be one of {', '.join(INTEGRATOR_NAMES)}; got {self.integrator!r}"
            )
        if self.spp < 1:
            raise ValueError(f"spp must be >= 1, got {self.spp}")
        if self.max_depth < 1:
            raise ValueError(f"max_depth must be >= 1, got {self.max_depth}")
        if self.russian_roulette < 0:
            raise ValueError(f"russian_roulette must be >= 0, got {self.russian_roulette}")
        if not self.gamma > 0.0:
            raise ValueError(f"gamma must be > 0, got {self.gamma}")

    def with_overrides(self, **overrides) -> RenderSettings:
        """A copy with the given keys changed (None values are ignored)."""
        names = {f.name for f in fields(self)}
        unknown = set(overrides) - names
        if unknown:
            raise ValueError(f"unknown render setting(s): {', '.join(sorted(unknown))}")
        return replace(self, **{k: v for k, v in overrides.items() if v is not None})
