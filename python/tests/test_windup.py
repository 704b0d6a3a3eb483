"""The windup figures and records from Python (issue 44; docs/windup.md): result["seat_rotation"] and
the others, result.summary["windup"] (the library's figures, as the command line's JSON), and the
deformed stack's S shape with the seat's turn drawn, headless (MPLBACKEND=Agg, as ctest sets it).

The run: tests/sweep/windup_small.toml, a flat leaf (1.2 m, 10 x 50 mm, E = 206 GPa, pinned eyes)
with the seat at a = 0.5 m held at w = 0 and wound +-0.02 rad at 1 Hz: each half a propped
cantilever, k_theta = 3 E I (1/a + 1/b), exact on the mesh (loads at nodes), so to 1e-9."""
import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import stackbeam
import stackbeam.plot
from conftest import SOURCE_DIR

E, B, T, L, A = 206e9, 0.05, 0.01, 1.2, 0.5
K_THETA = 3.0 * E * B * T ** 3 / 12.0 * (1.0 / A + 1.0 / (L - A))  # [N m/rad]


@pytest.fixture(scope="module")
def windup():
    scenario = stackbeam.load_scenario(str(SOURCE_DIR / "tests" / "sweep" / "windup_small.toml"))
    return stackbeam.simulate(scenario, nodes=True)


def test_seat_records_and_the_windup_figures(windup):
    theta, moment = np.asarray(windup["seat_rotation"]), np.asarray(windup["seat_moment"])
    assert len(theta) == len(windup["t"]) == len(windup["seat_axial"])
    assert theta.max() == pytest.approx(0.02, rel=1e-12)
    assert np.all(np.asarray(windup["seat_axial"]) == 0.0)  # pinned eyes: the seat holds the stack axially
    w = windup.summary["windup"]
    assert w["stiffness_n_m_per_rad"] == pytest.approx(K_THETA, rel=1e-9)
    # the same secant from the records: the last period's peak-to-peak moment over rotation
    last = np.asarray(windup["t"]) >= 1.0 - 1e-9
    secant = np.ptp(moment[last]) / np.ptp(theta[last])
    assert w["stiffness_n_m_per_rad"] == pytest.approx(secant, rel=1e-12)
    assert abs(w["loop_area_j"]) < 1e-12 * np.abs(moment).max() * 0.02  # a line: no area (elastic)
    assert w["loop"]["t_start_s"] == pytest.approx(1.0)
    assert w["vertical_rate_n_per_m"] is None and w["longitudinal_compliance_m_per_n"] is None


def test_the_tied_leaf_turns_with_the_seat(windup):
    """The nodes' rotation at the seat is the record's seat_rotation at every record (the seat is a
    plane section of the tied leaves): what the figure draws is what the records say."""
    nodes = windup.nodes
    seat = windup.scenario.model.rigid_body.x_m
    at = np.abs(np.asarray(nodes["x"]) - seat) < 1e-9
    assert np.allclose(np.asarray(nodes["theta"])[at], np.asarray(windup["seat_rotation"]), rtol=0, atol=1e-15)


def test_deformed_stack_draws_the_s_and_the_seat(windup):
    """Default times: the records of the largest and the smallest theta_R (w is held at 0); the seat's
    segment has the drawn slope scale x theta_R of that record; the S: the deflection antisymmetric
    in sign about the seat (up on one side, down on the other)."""
    fig = stackbeam.plot.deformed_stack(windup)
    scale = float(fig._suptitle.get_text().split(" x ")[-1])
    theta = np.asarray(windup["seat_rotation"])
    for ax, expected in zip(fig.axes, (theta.max(), theta.min())):
        assert "theta_R = %.4g mrad" % (1000 * expected) in ax.get_title()
        seat = next(line for line in ax.get_lines() if line.get_gid() == "seat")
        x, y = seat.get_xdata()[:2], seat.get_ydata()[:2]
        assert (y[1] - y[0]) / (x[1] - x[0]) == pytest.approx(scale * expected, rel=1e-9)
        leaf = ax.get_lines()[0]
        lx, ly = np.asarray(leaf.get_xdata()), np.asarray(leaf.get_ydata()) - leaf.get_ydata()[0]  # drawn deflection
        seat_mm = 1000 * windup.scenario.model.rigid_body.x_m
        left, right = ly[lx < seat_mm - 1], ly[lx > seat_mm + 1]
        # wound counter-clockwise: down before the seat, up after it (and the other way round)
        assert (np.sign(expected) * left).min() < 0 < (np.sign(expected) * right).max()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_a_seat_load_and_the_rig_unset_by_none():
    """None removes a seat load or the windup rig, as a scenario file without its table: the run is
    then the same spring without it (the seat held at w = 0 and nothing else: it does not turn, no moment)."""
    scenario = stackbeam.load_scenario(str(SOURCE_DIR / "tests" / "sweep" / "windup_small.toml"))
    assert scenario.model.loading.seat_rotation_rad is not None
    scenario.model.loading.seat_rotation_rad = None
    assert scenario.model.loading.seat_rotation_rad is None
    with pytest.raises(TypeError, match="loading.seat_moment_n_m"):
        scenario.model.loading.seat_moment_n_m = 3.0
    r = stackbeam.simulate(scenario, mode="closed-form")  # newmark massless takes the vertical rig only with the windup rig
    assert np.all(np.asarray(r["seat_rotation"]) == 0.0) and np.all(np.asarray(r["seat_moment"]) == 0.0)
