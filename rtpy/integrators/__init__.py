"""Integrators, one class each, in the order the course builds them."""

from ..render_settings import RenderSettings
from .center import CenterIntegrator
from .direct import DirectIntegrator
from .integrator import Integrator
from .jittered import JitteredIntegrator
from .path import PathIntegrator
from .shading import ShadingIntegrator
from .whitted import WhittedIntegrator

INTEGRATORS: dict[str, type[Integrator]] = {
    "center": CenterIntegrator,
    "jittered": JitteredIntegrator,
    "shading": ShadingIntegrator,
    "direct": DirectIntegrator,
    "whitted": WhittedIntegrator,
    "path": PathIntegrator,
}


def make_integrator(settings: RenderSettings) -> Integrator:
    return INTEGRATORS[settings.integrator](settings)


__all__ = [
    "INTEGRATORS",
    "CenterIntegrator",
    "DirectIntegrator",
    "Integrator",
    "JitteredIntegrator",
    "PathIntegrator",
    "ShadingIntegrator",
    "WhittedIntegrator",
    "make_integrator",
]
