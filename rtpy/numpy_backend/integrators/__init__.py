"""Batched integrators, one class each, twins of rtpy.integrators."""

from ...render_settings import RenderSettings
from .center import CenterIntegrator
from .direct import DirectIntegrator
from .integrator import BatchIntegrator
from .jittered import JitteredIntegrator
from .path import PathIntegrator
from .shading import ShadingIntegrator
from .whitted import WhittedIntegrator

INTEGRATORS: dict[str, type[BatchIntegrator]] = {
    cls.name: cls
    for cls in (
        CenterIntegrator,
        JitteredIntegrator,
        ShadingIntegrator,
        DirectIntegrator,
        WhittedIntegrator,
        PathIntegrator,
    )
}


def make_integrator(settings: RenderSettings) -> BatchIntegrator:
    return INTEGRATORS[settings.integrator](settings)


__all__ = ["INTEGRATORS", "BatchIntegrator", "make_integrator"]
