"""A parameter study on threads: the paper's friction spring's free vibration for several
clamp preloads, four runs at a time (each run releases the GIL, so they use the cores).
Prints the energy each preload dissipates in 0.6 s and the amplitude left at the end.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/parameter_study.py
"""
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import stackbeam

preloads_n = [250.0, 500.0, 1000.0, 2000.0]


def run(preload_n):
    s = stackbeam.paper_example("friction")
    for clamp in s.model.clamps:
        clamp.preload_n = preload_n
    r = stackbeam.simulate(s, t_end_s=0.6)
    last = r["t"] > 0.45  # the last quarter of the run
    return preload_n, r.summary["energy_j"]["dissipated"], np.abs(r["w"][last]).max()


with ThreadPoolExecutor(max_workers=4) as pool:
    rows = list(pool.map(run, preloads_n))
print("preload [N]  dissipated [J]  amplitude at the end [mm]")
for preload, dissipated, amplitude in rows:
    print("%11.0f  %14.4g  %25.4g" % (preload, dissipated, 1000 * amplitude))
