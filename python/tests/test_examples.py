"""The examples of examples/python run to the end (with the interpreter of the tests)."""
import os
import pathlib
import subprocess
import sys

import pytest

import stackbeam

from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"


@pytest.mark.parametrize("name", ["rig_loop.py", "parameter_study.py", "hand_built_spring.py"])
def test_example_runs(name, tmp_path):
    args = [sys.executable, str(EXAMPLES / name)]
    if name == "rig_loop.py":
        args.append(str(tmp_path))
    if name == "hand_built_spring.py":
        args.append(str(tmp_path / "spring.toml"))
    env = dict(os.environ, PYTHONPATH=str(pathlib.Path(stackbeam.__file__).resolve().parents[1]), MPLBACKEND="Agg")
    done = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    if name == "rig_loop.py":
        assert sorted(p.name for p in tmp_path.glob("rig_*.png")) == [
            "rig_displacement.png", "rig_force.png", "rig_friction.png", "rig_loop.png", "rig_stack.png"]
        assert (tmp_path / "rig_stack.gif").stat().st_size > 0
