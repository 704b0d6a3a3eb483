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


# --- Ctrl-C inside a long output interval, measured --------------------------------------------
#
# The child runs the friction case in mode cvode with one output interval of 1,000 s (about
# 100 s of work: nothing is recorded until its end), tells the parent when the run has started,
# and on KeyboardInterrupt prints time.monotonic(); the parent sends SIGINT and reads the
# latency on the same clock (CLOCK_MONOTONIC is system-wide). The stop check is polled every 64
# CVODE steps (about 3 ms here) and takes the GIL every 20 ms, so the latency is some 20 ms; the
# bound (2 s) leaves room for a loaded machine, and the figure is printed (pytest -s).
LONG_INTERVAL = r"""
import sys, time, stackbeam
scenario = stackbeam.paper_example("friction")
how = sys.argv[1]
print("started", time.monotonic(), flush=True)
try:
    if how == "simulate":
        stackbeam.simulate(scenario, mode="cvode", t_end_s=1000.0, dt_s=1000.0)
    elif how == "stepper":
        stepper = stackbeam.make_stepper(scenario, mode="cvode", t_end_s=1000.0, dt_s=1000.0)
        stepper.advance()
    print("finished", time.monotonic(), flush=True)
except KeyboardInterrupt:
    print("interrupted", time.monotonic(), flush=True)
    if how == "stepper":
        print("record_index", stepper.record_index, flush=True)
"""


@pytest.mark.parametrize("how", ["simulate", "stepper"])
def test_keyboard_interrupt_inside_a_long_output_interval_within_half_a_second(how):
    import subprocess
    import sys
    child = subprocess.Popen([sys.executable, "-c", LONG_INTERVAL, how], stdout=subprocess.PIPE, text=True,
                             env=os.environ)
    try:
        started = child.stdout.readline().split()
        assert started[0] == "started"
        time.sleep(1.0)  # well inside the interval (the model is built in some 10 ms)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
    lines = out.split("\n")
    word, when = lines[0].split()
    assert word == "interrupted", out
    latency_s = float(when) - sent
    print("%s: KeyboardInterrupt %.3f s after SIGINT" % (how, latency_s))
    assert latency_s < 2.0, latency_s  # issue 41 asks for 0.5 s; measured some 0.02 s
    if how == "stepper":
        assert lines[1] == "record_index 0"  # still at its last record


# --- a thread the system refuses ---------------------------------------------------------------
#
# The address space limited (RLIMIT_AS) to what the process uses plus 256 MiB: with 8 MiB of
# stack per thread some 30 threads fit, so 1,000 jobs fail to start; the sweep must stop the
# threads it started and raise ThreadStartError (Python) / exit with status 1 naming the
# failure (command line), where it aborted ("terminate called without an active exception").
SWEEP_UNDER_LIMIT = r"""
import resource, sys, stackbeam
with open("/proc/self/status") as f:
    vm = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))
resource.setrlimit(resource.RLIMIT_AS, (vm + (256 << 20), resource.RLIM_INFINITY))
try:
    stackbeam.sweep(sys.argv[1], jobs=1000)
    print("finished")
except stackbeam.ThreadStartError as e:
    print("ThreadStartError", e.errno, e)
"""


def test_a_thread_the_system_refuses_is_thread_start_error():
    import subprocess
    import sys
    from conftest import SOURCE_DIR
    spec = SOURCE_DIR / "tests" / "sweep" / "map_small.toml"
    done = subprocess.run([sys.executable, "-c", SWEEP_UNDER_LIMIT, str(spec)], capture_output=True, text=True,
                          timeout=300, env=os.environ)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("ThreadStartError"), done.stdout
    assert "could not start" in done.stdout and "jobs = 1000" in done.stdout


def test_the_command_line_under_a_thread_limit_exits_with_an_error(tmp_path):
    import resource
    import subprocess
    from conftest import CLI, SOURCE_DIR
    spec = SOURCE_DIR / "tests" / "sweep" / "map_small.toml"

    def limit():  # in the child: 512 MiB of address space (the command line itself uses some 100 MiB)
        resource.setrlimit(resource.RLIMIT_AS, (512 << 20, resource.RLIM_INFINITY))

    done = subprocess.run([CLI, "sweep", str(spec), "--jobs", "1000", "--out-dir", str(tmp_path / "out"), "--no-plot"],
                          capture_output=True, text=True, timeout=300, preexec_fn=limit)
    assert done.returncode == 1, (done.returncode, done.stderr[-2000:])
    assert "stackbeam: error: could not start the sweep's thread" in done.stderr, done.stderr
