"""stackbeam.fit: the same fit as `stackbeam fit`, value for value; a bad spec named."""
import json
import subprocess

import numpy as np
import pytest

import stackbeam
from conftest import CLI, SOURCE_DIR

SPEC = SOURCE_DIR / "examples" / "calibration" / "fit.toml"


def test_fit_matches_the_command_line(tmp_path):
    r = stackbeam.fit(SPEC, jobs=2)
    # the example's loops were made at friction_coefficient = 0.35 with 1 % force noise: within 2 %
    mu = r["parameters"][0]
    assert mu["identifiable"]
    assert abs(mu["value"] - 0.35) < 0.02 * 0.35
    assert mu["standard_error"] < 0.01 * 0.35
    assert len(r["loops"]) == 2 and r["loops"][0]["w_m"].shape == r["loops"][0]["fitted_force_n"].shape
    subprocess.run([str(CLI), "fit", str(SPEC), "--jobs", "1", "--out-dir", str(tmp_path), "--no-plot"], check=True,
                   capture_output=True)
    cli = json.loads((tmp_path / "fit.json").read_text())
    assert cli["parameters"][0]["value"] == mu["value"]  # threads and front end change nothing
    assert cli["runs"] == r["runs"]
    assert "friction_coefficient" in r["fitted_scenario"]


def test_fit_plot(tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import stackbeam.plot
    r = stackbeam.fit(SPEC, jobs=1)
    ax = stackbeam.plot.fit_loops(r)
    ax.figure.savefig(tmp_path / "loops.png")
    assert (tmp_path / "loops.png").stat().st_size > 0


def test_bad_spec_is_named(tmp_path):
    bad = tmp_path / "fit.toml"
    bad.write_text(SPEC.read_text().replace('"../../scenarios/', f'"{SOURCE_DIR}/scenarios/')
                   .replace('csv = "rig_loop_20mm.csv"', f'csv = "{SPEC.parent}/rig_loop_20mm.csv"')
                   .replace('csv = "rig_loop_10mm.csv"', f'csv = "{SPEC.parent}/rig_loop_10mm.csv"')
                   .replace('force_column = "load_cell_n"', 'force_column = "load_n"', 1))
    with pytest.raises(stackbeam.InputError, match=r"loops\[0\].force_column.*'load_n' is not a column"):
        stackbeam.fit(bad)
