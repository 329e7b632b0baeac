"""The installable package: every subpackage listed (an editable install hides a
missing one; a normal `pip install` would leave it out), the sdist holding the whole
test suite, the wheel the package alone, the license, and imports that work on every
system."""

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from .commands import modules_imported_by

ROOT = Path(__file__).resolve().parent.parent
TEST_WEEKS_FILE = "assignments/test_weeks.toml"  # rtpy's own repository has it, students' not


def test_every_subpackage_is_listed_in_pyproject():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    found = {
        ".".join(init.parent.relative_to(ROOT).parts)
        for init in (ROOT / "rtpy").rglob("__init__.py")
    }
    assert found <= listed, f"missing from pyproject packages: {sorted(found - listed)}"
    assert config["package-dir"]["rtpy.scenes"] == "scenes"
    assert (ROOT / "scenes" / "__init__.py").exists()


# Files of the repository that neither the sdist nor the wheel needs: CI's own script.
REPOSITORY_ONLY = (".ci/",)

# The distribution's files (MANIFEST.in, LICENSE, py.typed) are rtpy's own; a weekly
# student repository (rtpy.grading.assignment), which holds the week's folder of
# assignments/ alone, is a copy of rtpy's code without them.
rtpy_repository_only = pytest.mark.skipif(
    not (ROOT / TEST_WEEKS_FILE).exists(), reason="a student repository: rtpy's packaging only"
)


def manifest_files() -> set[str]:
    """The files MANIFEST.in puts in the sdist, found by the template engine the sdist
    command uses (setuptools' FileList), relative to the project root."""
    filelist = pytest.importorskip("setuptools._distutils.filelist")
    selected = filelist.FileList()
    selected.findall(str(ROOT))
    selected.allfiles = [str(Path(f).relative_to(ROOT)) for f in selected.allfiles]
    for line in (ROOT / "MANIFEST.in").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            selected.process_template_line(line)
    return set(selected.files)


def tracked_files() -> list[str]:
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout (an unpacked sdist)")
    listed = subprocess.run(
        ["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.splitlines()
    return [f for f in listed if (ROOT / f).is_file()]


@rtpy_repository_only
def test_the_sdist_holds_the_whole_test_suite_and_what_it_reads():
    """Every file of the repository is in the sdist: the package's through pyproject's
    packages, the others (tests, conftest, hard cases, the graders and their reference
    images, the docs the doc tests check) through MANIFEST.in."""
    packaged = ("rtpy/", "scenes/")
    expected = {f for f in tracked_files() if not f.startswith(REPOSITORY_ONLY + packaged)}
    missing = expected - manifest_files()
    assert not missing, f"MANIFEST.in leaves out {sorted(missing)[:10]}"
    assert {"tests/conftest.py", "LICENSE", "pyproject.toml"} <= expected


@rtpy_repository_only
def test_the_sdist_leaves_out_caches_and_render_outputs():
    """Binary files in the sdist are the graders' reference images, never a cache or
    an image rendered in the source tree."""
    binary = [f for f in manifest_files() if f.endswith((".npy", ".pfm", ".pyc"))]
    assert binary and all(f.startswith("assignments/week") for f in binary)
    assert all(Path(f).parent.name == "reference" for f in binary)


@rtpy_repository_only
def test_the_wheel_holds_the_rtpy_package_alone_with_its_type_marker():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    setuptools = config["tool"]["setuptools"]
    assert all(p == "rtpy" or p.startswith("rtpy.") for p in setuptools["packages"])
    assert setuptools["package-data"] == {
        "rtpy": ["py.typed"],
        "rtpy.scenes": ["*.toml", "*.png", "*.obj"],
    }
    assert (ROOT / "rtpy" / "py.typed").is_file()
    assert "Typing :: Typed" in config["project"]["classifiers"]


@rtpy_repository_only
def test_the_license_file_is_the_mit_license_pyproject_names():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    text = (ROOT / "LICENSE").read_text()
    assert project["license"] == "MIT" and text.startswith("MIT License\n")
    assert "Copyright (c) 2026 the rtpy authors" in text
    assert 'THE SOFTWARE IS PROVIDED "AS IS"' in text


def test_the_classifiers_name_every_python_version_rtpy_supports():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["requires-python"] == ">=3.11"
    versions = {
        c.rsplit(" ", 1)[1]
        for c in project["classifiers"]
        if c.startswith("Programming Language :: Python :: 3.")
    }
    assert {"3.11", "3.12", "3.13"} <= versions


# POSIX-only modules rtpy must never need at start-up (Windows has none of them).
POSIX_ONLY = ["resource", "fcntl", "termios", "pwd", "grp", "pty", "tty"]

IMPORT_EVERYTHING = """
import sys
for name in sys.argv[1:]:
    sys.modules[name] = None  # `import name` now raises ImportError, as on Windows
import importlib, math, pkgutil
import rtpy
names = [m.name for m in pkgutil.walk_packages(rtpy.__path__, "rtpy.")]
for name in names:
    if not name.endswith("__main__"):
        importlib.import_module(name)
from rtpy.testing.statistics import max_rss_mb, peak_memory_mb
assert math.isnan(max_rss_mb(children=False))  # the fallback without `resource`
peak = peak_memory_mb(children=True)
assert isinstance(peak, float) and (math.isnan(peak) or peak > 0)
print(len(names))
"""


def test_every_module_imports_without_posix_only_modules():
    """Every rtpy module (the command line, the bench, the graders...) imports in an
    interpreter where `resource` and the other POSIX-only modules cannot be imported,
    and peak memory falls back (NaN from getrusage, /proc where it exists)."""
    result = subprocess.run(
        [sys.executable, "-c", IMPORT_EVERYTHING, *POSIX_ONLY],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    modules = sum(1 for _ in (ROOT / "rtpy").rglob("*.py")) - 1  # all but __main__
    assert int(result.stdout) >= modules


WITHOUT_TEST_EXTRAS = """
import sys
for name in ("pytest", "hypothesis", "_pytest"):
    sys.modules[name] = None  # not installed: `pip install rtpy` without [test]
from rtpy.cli.main import main
sys.exit(main(["render", "--help"]))
"""


def test_the_command_line_starts_without_the_test_extras():
    """pytest and hypothesis are the `test` extra, not dependencies: the command line
    (whose `assignment` and `grade` commands use pytest) must start without them."""
    result = subprocess.run(
        [sys.executable, "-c", WITHOUT_TEST_EXTRAS], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stderr
    assert "--preview" in result.stdout


def test_import_rtpy_loads_neither_numpy_nor_pillow_nor_tqdm():
    """They are for rendering and writing images; the scene classes do without."""
    loaded = modules_imported_by("import rtpy")
    assert "rtpy.vec3" in loaded
    assert not loaded & {"numpy", "PIL", "tqdm", "importlib.metadata", "rtpy.engine.renderer"}
