"""The worker processes of a render receive a mesh with its tree, under every start
method, and never build one (rtpy.mesh.Mesh's pickled state)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from .tiers import slow_except

# A program run in its own interpreter with a start method forced. A plugin (which
# every worker loads before it unpickles the scene) makes any tree built outside the
# parent process an error, so a worker that rebuilds a mesh's tree stops the render.
NO_REBUILD_PROGRAM = """
import multiprocessing, os, sys
from pathlib import Path
import numpy as np
import rtpy
from rtpy.cli.bench.meshes import write_scene

if __name__ == "__main__":
    method, folder = sys.argv[1], Path(sys.argv[2])
    multiprocessing.set_start_method(method)
    os.environ["PARENT_PID"] = str(os.getpid())
    os.environ["PLANT"] = sys.argv[3]
    rtpy.load_plugin(folder / "guard.py")
    scene = rtpy.load_scene(write_scene(folder, 2000))
    for backend in sys.argv[4].split(","):
        one = rtpy.render(scene, width=24, spp=2, backend=backend, seed=5)
        two = rtpy.render(scene, width=24, spp=2, backend=backend, seed=5, workers=2)
        assert np.array_equal(one.linear, two.linear), backend
        print(backend, "same image")
"""

GUARD_PLUGIN = """
import os
import rtpy._bvh_build

_build = rtpy._bvh_build.build_tree

def guarded(*args, **kwargs):
    if os.getpid() != int(os.environ["PARENT_PID"]):
        raise RuntimeError("a worker process built a tree")
    return _build(*args, **kwargs)

rtpy._bvh_build.build_tree = guarded

if os.environ["PLANT"] == "plant":  # the mistake the check must catch: a mesh rebuilt
    from rtpy.mesh import Mesh

    keep = Mesh.__setstate__

    def rebuild(self, state):
        keep(self, state)
        self.tree = rtpy._bvh_build.build_tree(*self.triangle_boxes())

    Mesh.__setstate__ = rebuild
"""


def run_no_rebuild(tmp_path, method: str, backend: str = "scalar", plant: bool = False):
    """The program's run: renders by `backend` with 1 and 2 workers started by `method`."""
    (tmp_path / "guard.py").write_text(GUARD_PLUGIN)
    program = tmp_path / "program.py"
    program.write_text(NO_REBUILD_PROGRAM)
    plant_arg = "plant" if plant else "-"
    command = [sys.executable, str(program), method, str(tmp_path), plant_arg, backend]
    return subprocess.run(command, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("method", slow_except(["spawn", "forkserver", "fork"], "spawn"))
def test_workers_receive_the_mesh_and_its_tree_and_never_build_one(tmp_path, method):
    done = run_no_rebuild(tmp_path, method)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[0] == "scalar same image"


@pytest.mark.slow
def test_the_no_rebuild_check_catches_a_mesh_that_rebuilds_its_tree(tmp_path):
    done = run_no_rebuild(tmp_path, "spawn", plant=True)
    assert done.returncode != 0 and "a worker process built a tree" in done.stderr
