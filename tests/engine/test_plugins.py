"""Tests for rtpy.engine.plugins: plugin files loaded under a name every process agrees on."""

from __future__ import annotations

import subprocess
import sys

import pytest

from rtpy.engine.plugins import PLUGINS, PluginError, load_plugin, plugin_module_name
from rtpy.materials import MATERIALS

PLUGIN = (
    "from rtpy.materials import Lambertian, register_material\n"
    "RUNS = globals().get('RUNS', 0) + 1\n\n"
    '@register_material("plugin_test_grey")\n'
    "class PluginGrey(Lambertian):\n"
    "    pass\n"
)


@pytest.fixture
def clean_plugins():
    """PLUGINS, MATERIALS and sys.modules as they were before the test."""
    saved = dict(PLUGINS), dict(MATERIALS), set(sys.modules)
    yield
    PLUGINS.clear()
    PLUGINS.update(saved[0])
    MATERIALS.clear()
    MATERIALS.update(saved[1])
    for name in set(sys.modules) - saved[2]:
        del sys.modules[name]


def test_a_plugin_is_a_module_under_its_stable_name(tmp_path, clean_plugins):
    path = tmp_path / "my-materials.py"
    path.write_text(PLUGIN)
    module = load_plugin(path)
    name = plugin_module_name(path)
    assert module.__name__ == name and sys.modules[name] is module
    assert name.startswith("rtpy_plugin_my_materials_") and name.isidentifier()
    assert PLUGINS[name] == str(path.resolve())
    assert MATERIALS["plugin_test_grey"] is module.PluginGrey
    assert module.PluginGrey.__module__ == name  # what a pickle of its objects names


def test_the_name_is_the_same_in_another_process_and_from_another_directory(tmp_path):
    """A worker process (another interpreter, another working directory) derives the
    same module name from the same file; another file gets another name."""
    path = tmp_path / "plug.py"
    code = (
        "import sys; from rtpy.engine.plugins import plugin_module_name as n; print(n(sys.argv[1]))"
    )
    other = subprocess.run(
        [sys.executable, "-c", code, "plug.py"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=True,
    )
    assert other.stdout.strip() == plugin_module_name(path)
    assert plugin_module_name(tmp_path / "sub" / "plug.py") != plugin_module_name(path)


def test_loading_a_plugin_twice_runs_it_once(tmp_path, clean_plugins):
    path = tmp_path / "plug.py"
    path.write_text(PLUGIN)
    first = load_plugin(path)
    assert load_plugin(str(path)) is first and first.RUNS == 1


@pytest.mark.parametrize(
    "name,text,message",
    [
        ("plug.txt", PLUGIN, "not a .py file"),
        ("missing.py", None, "not a .py file"),
        ("broken.py", "1 / 0\n", "ZeroDivisionError: division by zero"),
        ("syntax.py", "def (:\n", "SyntaxError"),
    ],
)
def test_a_bad_plugin_is_refused_naming_the_file(tmp_path, clean_plugins, name, text, message):
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    with pytest.raises(PluginError, match=message) as err:
        load_plugin(path)
    assert str(err.value).startswith(str(path))
    assert plugin_module_name(path) not in sys.modules
    assert plugin_module_name(path) not in PLUGINS
