"""Runs on Python threads: the GIL is released while a run steps, so two runs overlap in time
and give the results of serial runs; Ctrl-C (SIGINT) stops a run with KeyboardInterrupt and
the process stays usable.

How overlap is proved without a wall-clock threshold (a shared, loaded machine): the main
thread samples the CPU clocks of the running threads (time.pthread_getcpuclockid). A run
that held the GIL would keep the main thread from sampling at all while it runs; so a sample
interval in which both runs' threads used CPU while both were inside simulate() shows both
stepping at once, with the main thread, which needs the GIL to sample, running too."""
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
    # CPU time both threads used at once, inside simulate(), in sample intervals while the
    # main thread ran Python: the smaller of the two threads' CPU increments, summed
    overlap_cpu_s = 0.0
    last = None
    while all(r.inside for r in runs):
        try:
            now = [cpu_s(r) for r in runs]
        except (OSError, TypeError):  # a thread ended between the check and the clock
            break
        if last is not None and all(r.inside for r in runs):
            overlap_cpu_s += max(0.0, min(n - l for n, l in zip(now, last)))
        last = now
        time.sleep(0.005)
    for r in runs:
        r.join()
    # The Python around the call (before and after the C++ run) takes well under 1 ms:
    # 20 ms of overlap is the C++ runs stepping at once.
    assert overlap_cpu_s > 0.02, overlap_cpu_s
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
