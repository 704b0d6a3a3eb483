"""A test-rig loop of the paper's friction spring (scenarios/rig_friction.toml): the rig strokes
the axle seat +-20 mm at 1 Hz; the figures of the run and the last cycle's loop figures, the
deformed stack at the extreme strokes (rig_stack.png) and an animation of it (rig_stack.gif).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/rig_loop.py [OUTDIR]
"""
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")

import stackbeam
import stackbeam.plot

here = pathlib.Path(__file__).resolve().parent
outdir = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
outdir.mkdir(parents=True, exist_ok=True)

scenario = stackbeam.load_scenario(str(here.parents[1] / "scenarios" / "rig_friction.toml"))
# two cycles (the second is the steady loop), with every leaf's nodes and every pair for the deformed stack
result = stackbeam.simulate(scenario, t_end_s=2.0, nodes=True, pairs=True)
loop = result.summary["hysteresis"]
print("loop of t = %.3g to %.3g s: area %.4g J per cycle, secant stiffness %.4g N/m, loss factor %.3g"
      % (loop["t_start_s"], loop["t_end_s"], loop["loop_area_j"], loop["secant_stiffness_n_per_m"], loop["loss_factor"]))
for f in stackbeam.plot.save_all(result, str(outdir / "rig")):  # rig_stack.png with the nodes
    print("figure", f)
every = max(1, len(result["t"]) // 50)  # about 50 frames over the run
print("animation", stackbeam.plot.animate_stack(result, outdir / "rig_stack.gif", every=every, fps=10))
