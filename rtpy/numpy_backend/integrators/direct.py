"""The "direct" integrator: emission plus one bounce of light (rtpy/integrators/direct.py)."""

from __future__ import annotations

from .path import PathIntegrator


class DirectIntegrator(PathIntegrator):
    """Emission seen directly plus light arriving after one reflection. This is
    exactly the "path" estimator with max_depth = 2, light sampling on and no
    Russian roulette (as the scalar DirectIntegrator documents), so it runs that."""

    name = "direct"

    def _limits(self) -> tuple[int, int, bool]:
        return 2, 0, True
