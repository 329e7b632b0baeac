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

from .._checks import one_line
from .user_files import read_bytes

# module name -> the plugin file it was loaded from, in loading order
PLUGINS: dict[str, str] = {}


class PluginError(Exception):
    """A plugin file that is not a .py file or fails while it is imported; the
    message is one line naming the file."""


def plugin_module_name(path: str | Path) -> str:
    """The module name of the plugin file at `path`: rtpy_plugin_<stem>_<8 hex digits
    of the resolved path's hash>, the same in every process on this machine."""
    resolved = Path(path).resolve()
    stem = re.sub(r"\W", "_", resolved.stem)
    digest = hashlib.sha256(str(resolved).encode()).hexdigest()[:8]
    return f"rtpy_plugin_{stem}_{digest}"


MAX_PLUGIN_BYTES = 10 << 20  # a plugin is a student's .py file, not data


def plugin_failure(err: BaseException) -> str:
    """What a plugin's error says, on one line: "TypeName: message" (line breaks
    escaped), or that it called sys.exit. The one wording of every failure of a
    plugin's code: at import, at registration, in a material's constructor."""
    if isinstance(err, SystemExit):
        return f"it called sys.exit({one_line(repr(err.code))})"
    text = one_line(str(err))
    return f"{type(err).__name__}: {text}" if text else type(err).__name__


def _run(module: ModuleType, source: str, path: str) -> None:
    """Run a plugin's source as `module` (listed in sys.modules meanwhile, so that its
    classes' pickles name it); PluginError naming `path` for anything it raises but a
    KeyboardInterrupt, sys.exit included (the module is then not kept)."""
    sys.modules[module.__name__] = module
    try:
        exec(compile(source, path, "exec"), module.__dict__)
    except (Exception, SystemExit) as err:
        del sys.modules[module.__name__]
        raise PluginError(f"{path}: {plugin_failure(err)}") from None
    except BaseException:
        del sys.modules[module.__name__]
        raise


def load_plugin(path: str | Path) -> ModuleType:
    """Import the .py file at `path` (once: a file loaded before is not run again) and
    return the module. Raises PluginError naming the file if it is not a regular .py
    file (rtpy.engine.user_files: a FIFO is not waited on), is not UTF-8, or raises
    while it runs (the module is then not kept)."""
    path = Path(path)
    if path.suffix != ".py":
        raise PluginError(f"{path}: not a .py file")
    name = plugin_module_name(path)
    if name in sys.modules:
        return sys.modules[name]
    resolved = path.resolve()
    try:
        source = _source(resolved)
    except OSError as err:
        raise PluginError(f"{path}: not a .py file ({err.strerror or err})") from None
    except UnicodeDecodeError as err:
        raise PluginError(f"{path}: not UTF-8 text (byte {err.start})") from None
    except SyntaxError as err:  # a coding declaration Python does not know
        raise PluginError(f"{path}: {plugin_failure(err)}") from None
    spec = importlib.util.spec_from_file_location(name, resolved)
    module = importlib.util.module_from_spec(spec)
    _run(module, source, str(resolved))
    PLUGINS[name] = str(resolved)
    return module


def load_listed_plugins(plugins: dict[str, str]) -> None:
    """Load the plugins another process listed in its PLUGINS (a worker's start-up)."""
    for path in plugins.values():
        load_plugin(path)


def plugin_sources() -> dict[str, tuple[str, str]]:
    """The plugins loaded here, for another machine: module name -> (the file's path
    here, its source)."""
    return {name: (path, _source(path)) for name, path in PLUGINS.items()}


def _source(path: str | Path) -> str:
    """The text of the plugin file at `path`, decoded as Python decodes a source file
    (UTF-8, a byte-order mark, a coding declaration), read through user_files."""
    return importlib.util.decode_source(read_bytes(path, MAX_PLUGIN_BYTES))


def load_plugin_source(name: str, source: str, path: str) -> ModuleType:
    """Run a plugin's `source` (from another machine's file `path`) as the module
    `name` that machine gave it (once). PluginError as load_plugin's."""
    if name in sys.modules:
        return sys.modules[name]
    module = ModuleType(name)
    module.__file__ = path
    _run(module, source, path)
    return module
