"""stackbeam.sweep: the same points table as `stackbeam sweep`, figure for figure; the same
table on one thread and on two; a bad spec refused before any run; the results directory."""
import csv
import math
import shutil
import subprocess

import numpy as np
import pytest

import stackbeam
from conftest import CLI, SOURCE_DIR

SPEC = SOURCE_DIR / "tests" / "sweep" / "map_small.toml"


def read_points_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def same_cell(python_value, text):
    """A table cell as points.csv writes it (round-trip digits; empty: NaN) against Python's value."""
    if isinstance(python_value, str):
        return python_value == text
    if text == "":
        return math.isnan(python_value)
    return float(text) == float(python_value)  # round-trip text: the same double


def test_equals_the_command_line_table(tmp_path):
    out = tmp_path / "cli"
    subprocess.run([CLI, "sweep", str(SPEC), "--jobs", "1", "--out-dir", str(out), "--no-plot"], check=True,
                   stdout=subprocess.DEVNULL)
    rows = read_points_csv(out / "points.csv")
    table = stackbeam.sweep(SPEC, jobs=1)
    assert len(rows) == len(table["point"]) == 8
    assert table.axes == ["loading.displacement_m.amplitude", "loading.displacement_m.frequency_hz",
                          "interfaces[*].friction_coefficient"]
    assert list(rows[0].keys())[: 4 + len(table.axes)][: 1 + len(table.axes)] == ["point"] + table.axes
    assert (table["status"] == "ok").all()
    for i, row in enumerate(rows):
        for name in ["point", *table.axes, "status", *table.figures]:
            assert same_cell(table[name][i].item() if hasattr(table[name][i], "item") else table[name][i],
                             row[name]), (i, name, table[name][i], row[name])


def test_two_threads_give_the_same_table():
    one = stackbeam.sweep(SPEC, jobs=1)
    two = stackbeam.sweep(SPEC, jobs=2)
    for name in ["point", *one.axes, *one.figures]:
        np.testing.assert_array_equal(one[name], two[name])
    assert list(one["status"]) == list(two["status"])


def test_results_directory_and_resume(tmp_path):
    out = tmp_path / "map"
    first = stackbeam.sweep(SPEC, jobs=2, out_dir=out)
    assert (out / "points.csv").exists() and (out / "sweep.json").exists()
    again = stackbeam.sweep(SPEC, jobs=2, out_dir=out)  # every point finished: none runs again
    for name in ["point", *first.figures]:
        np.testing.assert_array_equal(first[name], again[name])
    assert (again["wall_time_s"] == first["wall_time_s"]).all()  # read back from the journal, not rerun


def test_bad_spec_is_refused_before_any_run(tmp_path):
    bad = SOURCE_DIR / "tests" / "bad_sweep" / "unknown_key.toml"
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.sweep(bad, out_dir=tmp_path / "never")
    assert "unknown_key.toml" in str(e.value)
    assert not (tmp_path / "never").exists()
