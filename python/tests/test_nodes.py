"""The nodes' displacements from Python (Result.nodes, Stepper.nodes()) and the command line
(--nodes), and the deformed stack's figures (stackbeam.plot.deformed_stack, animate_stack),
headless (MPLBACKEND=Agg, as ctest sets it)."""
import os
import shutil
import subprocess

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import stackbeam
import stackbeam.plot
from conftest import CLI

STEPS = 40  # 40 ms of the paper's friction case at dt 1 ms: the stack slips and sticks within it


@pytest.fixture(scope="module")
def friction():
    scenario = stackbeam.paper_example("friction")
    return stackbeam.simulate(scenario, t_end_s=STEPS * scenario.simulation.dt_s, nodes=True, pairs=True)


def test_nodes_off_by_default():
    scenario = stackbeam.paper_example("friction")
    assert stackbeam.simulate(scenario, t_end_s=0.003).nodes is None


def test_result_nodes_whole_leaves_and_the_seat_at_w(friction):
    """Every record, every leaf whole (the half model mirrored: 2 x 20 elements), the seat's node
    moving with w (the same z: equal to round-off), the mirror image symmetric."""
    nodes = friction.nodes
    assert list(nodes) == ["t", "leaf", "x", "w", "theta"]
    t = friction["t"]
    assert len(nodes["t"]) == len(t) * 3 * 41
    seat = friction.scenario.model.rigid_body.x_m
    for i in (0, len(t) // 2, len(t) - 1):
        for leaf in range(3):
            at = (nodes["t"] == t[i]) & (nodes["leaf"] == leaf)
            x, w, theta = nodes["x"][at], nodes["w"][at], nodes["theta"][at]
            assert len(x) == 41 and x[0] == 0.0 and abs(x[-1] - 0.5) < 1e-15
            assert np.all(np.diff(x) > 0)
            np.testing.assert_array_equal(w, w[::-1])
            np.testing.assert_array_equal(theta, -theta[::-1])
            assert abs(x[20] - seat) < 1e-12
            assert w[20] == friction["w"][i]


def test_stepper_nodes_match_the_run(friction):
    stepper = stackbeam.make_stepper(stackbeam.paper_example("friction"), t_end_s=0.005)
    for _ in range(5):
        stepper.advance()
    n = stepper.nodes()
    assert list(n) == ["leaf", "x", "w", "theta"]
    at = friction.nodes["t"] == friction["t"][5]
    np.testing.assert_array_equal(n["w"], friction.nodes["w"][at])


def test_bad_nodes_option():
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.002, nodes="yes")
    assert e.value.field == "nodes"


def test_cli_nodes_file_is_the_python_run(friction, tmp_path):
    """The command line's --nodes file (long format t,leaf,x,w,theta at 17 digits) holds the same
    numbers as Result.nodes of the same run; --plot draws the deformed stack too."""
    out, nodes = tmp_path / "run.csv", tmp_path / "nodes.csv"
    cmd = [CLI, "simulate", "--case", "friction", "--t-end", str(STEPS * 1e-3), "--out", str(out), "--nodes", str(nodes),
           "--quiet"]
    if shutil.which("gnuplot"):
        cmd += ["--plot", str(tmp_path / "fig")]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    with open(nodes) as f:
        assert f.readline().strip() == "t,leaf,x,w,theta"
    table = np.loadtxt(nodes, delimiter=",", skiprows=1)
    for k, name in enumerate(["t", "leaf", "x", "w", "theta"]):
        np.testing.assert_array_equal(table[:, k], friction.nodes[name])
    if shutil.which("gnuplot"):
        assert (tmp_path / "fig_stack.png").stat().st_size > 0


def test_cli_nodes_bad_input(tmp_path):
    """--nodes naming the --out file is refused before any work (exit 2, the option named)."""
    out = tmp_path / "run.csv"
    r = subprocess.run([CLI, "simulate", "--case", "friction", "--t-end", "0.002", "--out", str(out), "--nodes", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert "--nodes" in r.stderr and "--out" in r.stderr
    assert not out.exists()


def test_deformed_stack_figure(friction, tmp_path):
    fig = stackbeam.plot.deformed_stack(friction, times=[0.0, 0.02])
    assert len(fig.axes) == 2
    assert "deflection drawn x" in fig._suptitle.get_text()
    ax = fig.axes[1]
    labels = {t.get_text() for t in ax.get_legend().get_texts()}
    assert labels <= {"stick", "slip", "open"} and labels
    assert len(ax.lines) == 3  # one axis per leaf
    fig.savefig(tmp_path / "stack.png")
    assert (tmp_path / "stack.png").stat().st_size > 0
    # the default: the extreme deflections, one scale (1, 2 or 5 x 10^k) stated on the figure
    fig = stackbeam.plot.deformed_stack(friction)
    scale = float(fig._suptitle.get_text().split(" x ")[-1])
    mantissa = scale / 10 ** np.floor(np.log10(scale))
    assert any(abs(mantissa - m) < 1e-9 for m in (1, 2, 5))
    # drawn: the top leaf's axis at the seat is its height plus scale times w (mm)
    i = int(np.argmax(friction["w"]))
    y = fig.axes[0].lines[0].get_ydata()
    geometry = stackbeam._core._stack_geometry(friction.scenario)
    assert abs(y[20] - 1000 * (geometry["axis_height_m"][0] + scale * friction["w"][i])) < 1e-9


def test_stack_scale_rule():
    assert stackbeam.plot.stack_scale(0.015, 0.03) == 1.0
    assert stackbeam.plot.stack_scale(0.015, 0.001) == 20.0
    assert stackbeam.plot.stack_scale(0.015, 0.0) == 1.0


def test_animate_stack_gif(friction, tmp_path):
    from PIL import Image

    path = stackbeam.plot.animate_stack(friction, tmp_path / "stack.gif", every=10)
    with Image.open(path) as im:
        assert im.format == "GIF"
        assert im.n_frames == len(range(0, len(friction["t"]), 10))


def test_figures_bad_input(friction, tmp_path):
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.plot.deformed_stack(friction, scale=-1.0)
    assert e.value.field == "scale"
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.plot.deformed_stack(friction, times=[99.0])
    assert e.value.field == "times"
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.plot.animate_stack(friction, tmp_path / "stack.avi")
    assert e.value.field == "path"
    no_nodes = stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.002)
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.plot.deformed_stack(no_nodes)
    assert e.value.field == "nodes"
