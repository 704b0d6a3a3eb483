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
