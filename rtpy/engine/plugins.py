"""Plugins: a student's .py file imported by path (its @register_material classes
become scene types), under a name every worker process can import it by.

A module loaded from a file path is not on sys.path, so a worker process started by
`spawn` or `forkserver` cannot import it by name when it rebuilds the scene. Each
plugin is therefore loaded under a name derived from its resolved path alone (the
same in every process) and listed in PLUGINS; the renderer's workers load the listed
plugins before they rebuild the scene. Workers on other machines (rtpy.engine.cluster) have
not the file: they receive its source (plugin_sources) and run it under the same name
(load_plugin_source).
"""

from __future__ import annotations

import hashlib
import importlib.util
import re
import sys
from pathlib import Path
from types import ModuleType

# module name -> the plugin file it was loaded from, in loading order
PLUGINS: dict[str, str] = {}


class PluginError(Exception):
    """A plugin file that is not a .py file or fails while it is imported."""


def plugin_module_name(path: str | Path) -> str:
    """The module name of the plugin file at `path`: rtpy_plugin_<stem>_<8 hex digits
    of the resolved path's hash>, the same in every process on this machine."""
    resolved = Path(path).resolve()
    stem = re.sub(r"\W", "_", resolved.stem)
    digest = hashlib.sha256(str(resolved).encode()).hexdigest()[:8]
    return f"rtpy_plugin_{stem}_{digest}"


def load_plugin(path: str | Path) -> ModuleType:
    """Import the .py file at `path` (once: a file loaded before is not run again) and
    return the module. Raises PluginError naming the file if it is not a .py file or
    raises while it runs (the module is then not kept)."""
    path = Path(path)
    if path.suffix != ".py" or not path.is_file():
        raise PluginError(f"{path}: not a .py file")
    name = plugin_module_name(path)
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path.resolve())
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # a class's pickle names this module
    try:
        spec.loader.exec_module(module)
    except Exception as err:
        del sys.modules[name]
        raise PluginError(f"{path}: {type(err).__name__}: {err}") from err
    PLUGINS[name] = str(path.resolve())
    return module


def load_listed_plugins(plugins: dict[str, str]) -> None:
    """Load the plugins another process listed in its PLUGINS (a worker's start-up)."""
    for path in plugins.values():
        load_plugin(path)


def plugin_sources() -> dict[str, tuple[str, str]]:
    """The plugins loaded here, for another machine: module name -> (the file's path
    here, its source)."""
    return {name: (path, Path(path).read_text(encoding="utf-8")) for name, path in PLUGINS.items()}


def load_plugin_source(name: str, source: str, path: str) -> ModuleType:
    """Run a plugin's `source` (from another machine's file `path`) as the module
    `name` that machine gave it (once). PluginError as load_plugin's."""
    if name in sys.modules:
        return sys.modules[name]
    module = ModuleType(name)
    module.__file__ = path
    sys.modules[name] = module
    try:
        exec(compile(source, path, "exec"), module.__dict__)
    except Exception as err:
        del sys.modules[name]
        raise PluginError(f"{path}: {type(err).__name__}: {err}") from err
    return module
