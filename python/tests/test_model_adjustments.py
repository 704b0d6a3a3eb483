"""What the library changed in the user's model is told with the run's answers
(Model::adjustments(), decision 077): two clamps closer than a tenth of mesh.element_length_m
are merged at their midpoint, and result.summary["model_adjustments"] names them as written.

tests/cli_close_clamps.toml: clamps[0] at 0.1 m and clamps[1] at 0.1004 m, 0.4 mm apart on
12.5 mm elements (0.1 h = 1.25 mm), 10 mm long on an elastic interface (neither a rigid tie):
merged at (0.1 + 0.1004) / 2 = 0.1002 m. The paper's friction case has no close clamps: no key."""
import stackbeam
from conftest import SOURCE_DIR


def test_merged_clamps_are_named_in_the_summary():
    s = stackbeam.load_scenario(str(SOURCE_DIR / "tests" / "cli_close_clamps.toml"))
    r = stackbeam.simulate(s)
    notes = r.summary["model_adjustments"]
    assert len(notes) == 1
    assert notes[0].startswith("clamps[0] (x = 0.1 m) and clamps[1] (x = 0.1004 m), 0.0004 m apart, "
                               "act as one clamp at x = 0.1002 m, their preloads and lengths added")
    assert "mesh.element_length_m (0.00125 m of 0.0125 m)" in notes[0]
    # the scenario object keeps what the user wrote: the merge is the model's, told, not written back
    assert s.model.clamps[1].x_m == 0.1004


def test_no_close_clamps_no_key():
    r = stackbeam.simulate(stackbeam.paper_example("friction"), t_end_s=0.002)
    assert "model_adjustments" not in r.summary
