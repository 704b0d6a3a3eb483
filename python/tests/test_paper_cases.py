"""The paper's three cases from Python equal the command line's runs of the same C++ library:
every record's CSV text (the CLI writes %.12g), every pair at every record bit for bit (the
--pairs file has 17 digits: a double's exact round trip) and the JSON summary's every number
(nlohmann writes a double's round trip) but the wall time and the file names."""
import csv
import json
import subprocess

import numpy as np
import pytest

import stackbeam
from conftest import CLI


def cli_run(tmp_path, *args):
    out, summary, pairs = tmp_path / "run.csv", tmp_path / "run.json", tmp_path / "pairs.csv"
    subprocess.run([CLI, "simulate", *args, "--out", str(out), "--summary", str(summary), "--pairs", str(pairs),
                    "--quiet"], check=True, stdout=subprocess.DEVNULL)
    return out.read_text(), json.loads(summary.read_text()), pairs


def csv_text(result):
    """The records as the command line writes them (write_csv_row: %.12g)."""
    names = list(result)
    lines = [",".join(names)]
    for i in range(len(result["t"])):
        lines.append(",".join("%.12g" % result[n][i] for n in names))
    return "\n".join(lines) + "\n"


def without_run_details(summary):
    s = dict(summary)
    s.pop("wall_time_s")
    s.pop("outputs")
    return s


@pytest.mark.parametrize("case", ["bonded", "friction", "frictionless"])
def test_paper_case_equals_command_line(tmp_path, case):
    text, summary, pairs_file = cli_run(tmp_path, "--case", case)
    result = stackbeam.simulate(stackbeam.paper_example(case), pairs=True)
    assert csv_text(result) == text
    assert without_run_details(result.summary) == without_run_details(summary)
    with open(pairs_file) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(result.pairs["t"])
    for key in ["t", "x", "p_n", "p_t", "gap", "slip"]:
        np.testing.assert_array_equal(np.array([float(r[key]) for r in rows]), result.pairs[key])
    for key in ["pair", "interface"]:
        np.testing.assert_array_equal(np.array([int(r[key]) for r in rows]), result.pairs[key])
    assert [r["state"] for r in rows] == list(result.pairs["state"])


def test_cvode_case_and_its_event_log_equal_command_line(tmp_path):
    """Mode cvode: the records and the event log (the --events file) too."""
    events = tmp_path / "events.csv"
    text, summary, _ = cli_run(tmp_path, "--case", "friction", "--mode", "cvode", "--t-end", "0.1",
                               "--events", str(events))
    result = stackbeam.simulate(stackbeam.paper_example("friction"), mode="cvode", t_end_s=0.1)
    assert csv_text(result) == text
    assert without_run_details(result.summary) == without_run_details(summary)
    with open(events) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(result.events["t"]) > 0
    assert [r["to"] for r in rows] == list(result.events["to"])
    np.testing.assert_array_equal([int(r["pair"]) for r in rows], result.events["pair"])
    np.testing.assert_array_equal(["%.15g" % t for t in result.events["t"]], [r["t"] for r in rows])


def test_scenario_file_equals_command_line(tmp_path, scenarios):
    """A scenario file's run (the rig loop: a periodic loading, so the summary's hysteresis figures too)."""
    path = scenarios / "rig_friction.toml"
    text, summary, _ = cli_run(tmp_path, "--scenario", str(path), "--t-end", "1.0")
    result = stackbeam.simulate(stackbeam.load_scenario(str(path)), t_end_s=1.0)
    assert csv_text(result) == text
    assert without_run_details(result.summary) == without_run_details(summary)
    assert result.summary["hysteresis"] is not None
