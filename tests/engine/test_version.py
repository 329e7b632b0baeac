"""rtpy.engine.version: the installed package's version, and a source tree's."""

from __future__ import annotations

from importlib import metadata

import rtpy
from rtpy.engine import version as version_module


def test_the_version_is_the_installed_packages(monkeypatch):
    assert version_module.version() == metadata.version("rtpy") == rtpy.__version__
    version_module.version.cache_clear()

    def missing(name):
        raise metadata.PackageNotFoundError(name)

    monkeypatch.setattr(metadata, "version", missing)
    try:
        assert version_module.version() == "0+unknown"
    finally:
        version_module.version.cache_clear()
