"""The stresses from Python (simulate(..., stresses=True): Result.stresses and
Result.summary["stresses"]) and their figure (stackbeam.plot.stresses), headless (MPLBACKEND=Agg)."""
import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import stackbeam
import stackbeam.plot

STEPS = 20  # 20 ms of the paper's friction case at dt 1 ms: the stack bends under the load


@pytest.fixture(scope="module")
def friction():
    scenario = stackbeam.paper_example("friction")
    return stackbeam.simulate(scenario, t_end_s=STEPS * scenario.simulation.dt_s, stresses=True)


def test_stresses_off_by_default():
    result = stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.003)
    assert result.stresses is None
    assert "stresses" not in result.summary


def test_stresses_bad_flag_names_it():
    with pytest.raises(stackbeam.InputError, match="stresses"):
        stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.003, stresses=1)


def test_result_stresses_whole_leaves_and_fibre_balance(friction):
    """Every record, every leaf whole (2 x 20 elements: 41 nodes), and the fibre stresses from the
    resultants as post/stresses.hpp states them: sigma_top + sigma_bottom = 2 N / (b t) and
    sigma_bottom - sigma_top = 12 M / (b t^2), with the paper's leaves' b and t (uniform leaves);
    to round-off of the stresses' size (1e-9 relative: a few operations in double)."""
    leaves = friction.stresses
    assert len(leaves) == 3
    spec = friction.scenario.model
    for k, leaf in enumerate(leaves):
        assert leaf["leaf"] == k
        assert leaf["sigma_top"].shape == (len(friction["t"]), 41)
        np.testing.assert_array_equal(leaf["t"], friction["t"])
        b, t = spec.leaves[k].width_m, spec.leaves[k].height_m
        scale = np.abs(leaf["sigma_top"]).max()
        assert scale > 0.0
        np.testing.assert_allclose(leaf["sigma_top"] + leaf["sigma_bottom"], 2 * leaf["N"] / (b * t), rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(leaf["sigma_bottom"] - leaf["sigma_top"], 12 * leaf["M"] / (b * t * t), rtol=0, atol=1e-9 * scale)


def test_summary_extremes_are_the_arrays_extremes(friction):
    """The summary's largest tension and compression per leaf are the greatest and least of the
    arrays over both fibres, nodes and records (the same numbers: one computation)."""
    section = friction.summary["stresses"]
    assert section["samples"] == len(friction["t"])
    for leaf, s in zip(friction.stresses, section["leaves"]):
        both = np.concatenate([leaf["sigma_top"], leaf["sigma_bottom"]])
        assert s["largest_tension"]["stress_pa"] == both.max()
        assert s["largest_compression"]["stress_pa"] == both.min()
        assert s["fatigue"] is None  # the paper's leaves have no material
    assert len(section["interfaces"]) == 2


def test_plot_stresses(friction):
    fig = stackbeam.plot.stresses(friction, times=[0.005, 0.02])
    assert len(fig.axes) == 3
    with pytest.raises(stackbeam.InputError, match="result.stresses"):
        stackbeam.plot.stresses(stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.002))


@pytest.fixture(scope="module")
def friction_nodes():
    scenario = stackbeam.paper_example("friction")
    return stackbeam.simulate(scenario, t_end_s=STEPS * scenario.simulation.dt_s, nodes=True, stresses=True)


def test_deformed_stack_coloured_by_stress(friction_nodes):
    """deformed_stack(color_by="stress"): per time, each leaf a mesh whose colour data is
    result.stresses' sigma_bottom and sigma_top at that record in MPa, node for node (the same
    numbers divided by 1e6: equal to round-off, 1e-12 relative), its edges the leaf's thickness
    apart, one colour scale symmetric about 0 whose limits are the largest |stress| drawn, and a
    colour bar in MPa per panel."""
    r = friction_nodes
    times = [0.01, 0.02]
    fig = stackbeam.plot.deformed_stack(r, times=times, color_by="stress")
    t = r["t"]
    panels = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    assert len(panels) == 2
    peak = 0.0
    spec = r.scenario.model
    for a, ti in zip(panels, times):
        i = int(np.argmin(np.abs(t - ti)))
        by_gid = {c.get_gid(): c for c in a.collections if c.get_gid()}
        assert len(by_gid) == len(r.stresses)
        for leaf in r.stresses:
            mesh = by_gid["leaf %d" % leaf["leaf"]]
            expected = np.vstack([leaf["sigma_bottom"][i], leaf["sigma_top"][i]]) / 1e6
            np.testing.assert_allclose(np.asarray(mesh.get_array()).reshape(expected.shape), expected, rtol=1e-12, atol=0)
            corners = np.asarray(mesh.get_coordinates())  # (2, nodes, 2): bottom and top edge, (x, y) [mm]
            np.testing.assert_allclose(corners[:, :, 0], 1000 * np.vstack([leaf["x"], leaf["x"]]), rtol=1e-12)
            np.testing.assert_allclose(corners[1, :, 1] - corners[0, :, 1], 1000 * spec.leaves[leaf["leaf"]].height_m,
                                       rtol=1e-9)
            peak = max(peak, np.abs(expected).max())
            assert mesh.norm.vmin == -mesh.norm.vmax
    mesh = next(c for c in panels[0].collections if c.get_gid())
    assert mesh.norm.vmax == pytest.approx(peak, rel=1e-12)
    bars = [a for a in fig.axes if a.get_label() == "<colorbar>"]
    assert len(bars) == 2 and "MPa" in bars[0].get_ylabel()


def test_deformed_stack_colour_refusals(friction_nodes, friction):
    with pytest.raises(stackbeam.InputError, match="color_by"):
        stackbeam.plot.deformed_stack(friction_nodes, color_by="pressure")
    # stresses without nodes: the nodes named; nodes without stresses: result.stresses named
    with pytest.raises(stackbeam.InputError, match="nodes"):
        stackbeam.plot.deformed_stack(friction, color_by="stress")
    no_stresses = stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.002, nodes=True)
    with pytest.raises(stackbeam.InputError, match="result.stresses"):
        stackbeam.plot.deformed_stack(no_stresses, color_by="stress")


def test_scenario_key_stresses_path():
    """Scenario.outputs.stresses_path, the file key [outputs] stresses_path (the command line's
    --stresses): written by to_toml, read back; a non-string refused by its name."""
    s = stackbeam.paper_example("friction")
    assert s.outputs.stresses_path == ""
    s.outputs.stresses_path = "stresses.csv"
    assert 'stresses_path = "stresses.csv"' in s.to_toml()
    assert stackbeam.Scenario.from_toml(s.to_toml(), "back").outputs.stresses_path == "stresses.csv"
    with pytest.raises(stackbeam.InputError, match="outputs.stresses_path"):
        s.outputs.stresses_path = 3
