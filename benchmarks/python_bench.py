"""Python module benchmarks (docs/performance.md, "Python"): the overhead of stackbeam.simulate
over the same run by the C++ command line, and two runs on two Python threads against one.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_bench.py [--repeat N] [--cli build/apps/cli/stackbeam]

1. Overhead, the paper friction case (closed-form, 0.6 s, 600 steps), repeated interleaved:
   - python: wall and CPU time of simulate() (the model's build, the run, the numpy arrays,
     the summary), against
   - C++ inside it: the run's own wall time (Result.summary["wall_time_s"], from the System's
     build to the records), and
   - the command line: `stackbeam simulate --case friction` (its summary's wall_time_s: the
     same run writing its CSV; and the child's CPU time, process start included).
2. Threads: the friction case to t = 10 s, one run alone, then two runs on two threads at once,
   in interleaved rounds with a control (the same run in one and two Python processes at once);
   the ratio of the wall times (two at once / one), and of the CPU time per run (two at once
   / one: above 1 if the runs slowed each other down, e.g. by a lock). The wall ratio needs
   two idle cores: the load average is printed with it.
Medians over the repetitions; timings of a shared machine are noisy (compare ratios).
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import stackbeam

parser = argparse.ArgumentParser()
parser.add_argument("--repeat", type=int, default=7)
parser.add_argument("--cli", default=os.path.join("build", "apps", "cli", "stackbeam"))
args = parser.parse_args()

scenario = stackbeam.paper_example("friction")


def python_run():
    w0, c0 = time.perf_counter(), time.process_time()
    r = stackbeam.simulate(scenario)
    return time.perf_counter() - w0, time.process_time() - c0, r.summary["wall_time_s"]


def cli_run(tmp):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([args.cli, "simulate", "--case", "friction", "--out", os.path.join(tmp, "f.csv"),
                    "--summary", os.path.join(tmp, "f.json"), "--quiet"], check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    with open(os.path.join(tmp, "f.json")) as f:
        return json.load(f)["wall_time_s"], cpu


py_wall, py_cpu, py_inner, cli_wall, cli_cpu = [], [], [], [], []
with tempfile.TemporaryDirectory() as tmp:
    python_run()  # warm up (imports, caches)
    for _ in range(args.repeat):
        w, c, inner = python_run()
        py_wall.append(w), py_cpu.append(c), py_inner.append(inner)
        w, c = cli_run(tmp)
        cli_wall.append(w), cli_cpu.append(c)
med = statistics.median
print("1. paper friction case, closed-form, 600 steps; medians of %d" % args.repeat)
print("   python simulate(): wall %.4f s, CPU %.4f s" % (med(py_wall), med(py_cpu)))
print("   its C++ run:       wall %.4f s   -> python layer overhead %+.1f %%" % (
    med(py_inner), 100 * (med(py_wall) / med(py_inner) - 1)))
print("   command line:      wall %.4f s (run + CSV), CPU %.4f s (process)   -> python vs CLI: wall %+.1f %%, CPU %+.1f %%" % (
    med(cli_wall), med(cli_cpu), 100 * (med(py_wall) / med(cli_wall) - 1), 100 * (med(py_cpu) / med(cli_cpu) - 1)))

long_run = {"t_end_s": 10.0}


def timed(n_threads):
    results = [None] * n_threads

    def work(i):
        results[i] = stackbeam.simulate(scenario, **long_run)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(n_threads)]
    w0, c0 = time.perf_counter(), time.process_time()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.perf_counter() - w0, time.process_time() - c0


CHILD = """
import sys, time, stackbeam
scenario = stackbeam.paper_example("friction")
stackbeam.simulate(scenario, t_end_s=0.1)  # warm up, as the threads' process is
while time.time() < float(sys.argv[1]):  # start together
    time.sleep(0.0005)
w0 = time.perf_counter()
stackbeam.simulate(scenario, t_end_s=10.0)
print(time.perf_counter() - w0)
"""


def processes(n_procs, tmp):
    """The control: the same run in n_procs Python processes at once (no shared process, no
    shared GIL), started together; the longest run's wall time, as a round of threads waits for
    its slower run."""
    del tmp
    at = time.time() + 1.0
    procs = [subprocess.Popen([sys.executable, "-c", CHILD, repr(at)], stdout=subprocess.PIPE, text=True)
             for _ in range(n_procs)]
    walls = []
    for p in procs:
        out, _ = p.communicate()
        if p.returncode != 0:
            raise RuntimeError("the control process failed")
        walls.append(float(out))
    return max(walls)


rounds = {"one": [], "two": [], "one_cpu": [], "two_cpu": [], "p1": [], "p2": []}
with tempfile.TemporaryDirectory() as tmp:
    for _ in range(args.repeat):  # interleaved rounds: the machine's speed drifts between them
        w, c = timed(1)
        rounds["one"].append(w), rounds["one_cpu"].append(c)
        w, c = timed(2)
        rounds["two"].append(w), rounds["two_cpu"].append(c)
        rounds["p1"].append(processes(1, tmp))
        rounds["p2"].append(processes(2, tmp))
ratio = lambda a, b: med([y / x for x, y in zip(rounds[a], rounds[b])])
print("2. friction case to t = 10 s (10,000 steps); medians of %d interleaved rounds; %d cores, load average %.1f" % (
    args.repeat, os.cpu_count(), os.getloadavg()[0]))
print("   one run:               wall %.3f s, CPU %.3f s" % (med(rounds["one"]), med(rounds["one_cpu"])))
print("   two runs, two threads: wall %.3f s, CPU %.3f s   -> %.3fx the wall time of one, %.3fx the CPU time per run" % (
    med(rounds["two"]), med(rounds["two_cpu"]), ratio("one", "two"),
    med([c2 / 2 / c1 for c1, c2 in zip(rounds["one_cpu"], rounds["two_cpu"])])))
print("   control, two Python processes at once (no shared process, no GIL): %.3fx the wall time of one run"
      " (the machine's own two-core scaling)" % ratio("p1", "p2"))
