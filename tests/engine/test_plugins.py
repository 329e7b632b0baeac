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


BAD_PLUGINS = {
    "a message of two lines": (
        "raise RuntimeError('first line\\nsecond line')\n",
        "RuntimeError: first line\\nsecond line",
    ),
    "sys.exit(0) at import": ("import sys\nsys.exit(0)\n", "it called sys.exit(0)"),
    "sys.exit with a message": (
        "raise SystemExit('bye\\nnow')\n",
        "it called sys.exit('bye\\nnow')",
    ),
    "a name that is not a string": (
        "from rtpy.materials import Lambertian, register_material\n"
        "@register_material(3)\nclass A(Lambertian):\n    pass\n",
        "TypeError: register_material: the name must be a non-empty string, got 3",
    ),
    "a registered function": (
        "from rtpy.materials import register_material\n"
        "@register_material('fn')\ndef make():\n    pass\n",
        "TypeError: register_material('fn'): expected a subclass of Material, got <function",
    ),
    "an exception without a message": ("raise LookupError\n", "LookupError"),
    "not UTF-8": (b"x = '\xff'\n", "SyntaxError: invalid or missing encoding declaration"),
}


@pytest.mark.parametrize("case", BAD_PLUGINS)
def test_every_failure_of_a_plugin_is_one_line_naming_the_file(tmp_path, clean_plugins, case):
    text, message = BAD_PLUGINS[case]
    path = tmp_path / "bad.py"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(PluginError) as caught:
        load_plugin(path)
    said = str(caught.value)
    assert said.startswith(f"{path}: ") and message in said and "\n" not in said, said
    assert plugin_module_name(path) not in sys.modules and "fn" not in MATERIALS


def test_a_plugin_sent_to_another_machine_fails_the_same_way(clean_plugins):
    from rtpy.engine.plugins import load_plugin_source

    with pytest.raises(PluginError, match=r"^there\.py: it called sys\.exit\(3\)$"):
        load_plugin_source("rtpy_plugin_there_0", "import sys\nsys.exit(3)\n", "there.py")
    assert "rtpy_plugin_there_0" not in sys.modules


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="no FIFOs here")
def test_a_plugin_path_that_is_a_fifo_is_refused_at_once(tmp_path, clean_plugins):
    import os

    path = tmp_path / "pipe.py"
    os.mkfifo(path)
    with pytest.raises(PluginError, match="not a .py file .*FIFO"):
        load_plugin(path)


def test_a_material_constructor_that_raises_is_one_line_naming_table_and_key(
    tmp_path, clean_plugins
):
    from rtpy.io.scene_file import SceneError, load_scene

    path = tmp_path / "raising.py"
    path.write_text(
        "from rtpy.materials import Lambertian, register_material\n"
        "@register_material('raising')\nclass Raising(Lambertian):\n"
        "    def __init__(self, level: float = 0.5):\n"
        "        raise RuntimeError('not today\\nor tomorrow')\n"
    )
    load_plugin(path)
    scene = tmp_path / "s.toml"
    scene.write_text(
        '[materials.m]\ntype = "raising"\n[[objects]]\ntype = "sphere"\n'
        'center = [0, 0, -1]\nradius = 0.5\nmaterial = "m"\n'
    )
    with pytest.raises(SceneError) as caught:
        load_scene(scene)
    said = str(caught.value)
    assert caught.value.key == "type" and "[materials.m]" in said and "\n" not in said
    assert 'the "raising" constructor failed: RuntimeError: not today\\nor tomorrow' in said


def test_a_plugin_is_decoded_as_python_decodes_a_file(tmp_path, clean_plugins):
    (tmp_path / "bom.py").write_bytes(b"\xef\xbb\xbfX = 1\n")
    (tmp_path / "latin.py").write_bytes(b"# -*- coding: latin-1 -*-\nX = '\xe9'\n")
    assert load_plugin(tmp_path / "bom.py").X == 1
    assert load_plugin(tmp_path / "latin.py").X == "\xe9"
