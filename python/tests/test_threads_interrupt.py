"""Runs on Python threads: the GIL is released while a run steps, so two runs overlap in time
and give the results of serial runs; Ctrl-C (SIGINT) stops a run with KeyboardInterrupt and
the process stays usable.

How overlap is proved without a wall-clock threshold (a shared, loaded machine): the main
thread samples the CPU clocks of the two running threads (time.pthread_getcpuclockid) with
time.monotonic(); each run reports when it stepped without the GIL (report["without_gil_s"],
on the same clock). A sample interval that lies inside both runs' GIL-free stepping and in
which both threads used CPU shows both runs stepping in it, while the main thread, which
needs the GIL to sample, ran too. Runs serialised by the GIL would give no such interval.
"""
import os
import signal
import threading
import time

import numpy as np
import pytest

import stackbeam


def friction(t_end_s):
    return stackbeam.paper_example("friction"), {"t_end_s": t_end_s}


class Run(threading.Thread):
    def __init__(self, scenario, options):
        super().__init__()
        self.scenario, self.options = scenario, options
        self.inside = False
        self.result = None

    def run(self):
        self.inside = True
        try:
            self.result = stackbeam.simulate(self.scenario, **self.options)
        finally:
            self.inside = False


def cpu_s(thread):
    return time.clock_gettime(time.pthread_getcpuclockid(thread.ident))


def test_two_runs_on_two_threads_overlap_and_equal_serial():
    scenario, options = friction(20.0)  # about 1 s of CPU per run
    serial = stackbeam.simulate(scenario, **options)
    runs = [Run(scenario, options), Run(scenario, options)]
    for r in runs:
        r.start()
    while not all(r.inside for r in runs) and any(r.is_alive() for r in runs):
        time.sleep(0.001)
    samples = []  # (time.monotonic() before, CPU time of each thread, time.monotonic() after)
    while all(r.inside for r in runs):
        try:
            before = time.monotonic()
            samples.append((before, [cpu_s(r) for r in runs], time.monotonic()))
        except (OSError, TypeError):  # a thread ended between the check and the clock
            break
        time.sleep(0.005)
    for r in runs:
        r.join()
    start = max(r.result.report["without_gil_s"][0] for r in runs)
    end = min(r.result.report["without_gil_s"][1] for r in runs)
    both_stepping = sum(
        1 for (t0, c0, _), (_, c1, t1) in zip(samples, samples[1:])
        if start <= t0 and t1 <= end and all(b > a for a, b in zip(c0, c1)))
    assert both_stepping >= 1, (len(samples), start, end)
    for r in runs:
        for name in serial:
            np.testing.assert_array_equal(r.result[name], serial[name])


def test_keyboard_interrupt_stops_a_run_and_leaves_the_process_usable():
    scenario, _ = friction(0.6)
    reference = stackbeam.simulate(scenario, t_end_s=0.05)
    started = threading.Event()

    def interrupt():
        started.wait()
        time.sleep(0.2)
        os.kill(os.getpid(), signal.SIGINT)

    killer = threading.Thread(target=interrupt)
    killer.start()
    # 1,000 s of simulated time: minutes of work, stopped by the signal after about 0.2 s
    with pytest.raises(KeyboardInterrupt) as e:
        started.set()
        stackbeam.simulate(scenario, t_end_s=1000.0)
    killer.join()
    assert e.traceback[-1].name == "simulate"  # raised by the run, not before it
    again = stackbeam.simulate(scenario, t_end_s=0.05)
    for name in reference:
        np.testing.assert_array_equal(again[name], reference[name])


FIRST_RUNS_AT_ONCE = """
import threading, stackbeam
scenario = stackbeam.paper_example("friction")
start = threading.Barrier(2)
def work():
    start.wait()
    stackbeam.simulate(scenario, t_end_s=0.05)
threads = [threading.Thread(target=work) for _ in range(2)]
for t in threads: t.start()
for t in threads: t.join()
print("done")
"""


def test_first_runs_of_a_process_on_two_threads_at_once():
    # the first arrays a process makes look up numpy's C API; two runs finishing together on
    # two threads deadlocked there (pybind11 2.10's lookup in a function-local static, importing
    # numpy under the static's guard) in 10 tries of 10 before the module looked it up at import
    import subprocess
    import sys
    for _ in range(3):
        done = subprocess.run([sys.executable, "-c", FIRST_RUNS_AT_ONCE], capture_output=True, text=True,
                              timeout=120, env=os.environ)
        assert done.returncode == 0, done.stderr
        assert done.stdout.strip() == "done"
