"""A spring built from Python objects, no file: a graduated two-leaf spring (the lower leaf
shorter), clamped near the seat, loaded by a harmonic force on the axle; written out as a
scenario file and run.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/hand_built_spring.py [OUT.toml]
"""
import sys

import stackbeam

s = stackbeam.Scenario()
s.description = "graduated two-leaf spring built in Python, harmonic force on the axle"
for length_m, x_start_m in [(1.0, 0.0), (0.6, 0.2)]:
    leaf = stackbeam.Leaf()
    leaf.length_m, leaf.x_start_m = length_m, x_start_m
    leaf.height_m, leaf.width_m = 0.007, 0.06
    leaf.youngs_modulus_pa = 2.0e11
    s.model.leaves.append(leaf)
s.model.leaves[0].left_support = s.model.leaves[0].right_support = "pinned"
interface = stackbeam.Interface()
interface.law, interface.friction_coefficient = "coulomb", 0.3
s.model.interfaces.append(interface)
for x_m in (0.4, 0.6):
    clamp = stackbeam.Clamp()
    clamp.x_m, clamp.preload_n = x_m, 2000.0
    s.model.clamps.append(clamp)
s.model.rigid_body.mass_kg, s.model.rigid_body.x_m = 50.0, 0.5
s.model.loading.kind = "applied-force"
force = s.model.loading.force_n
force.shape, force.amplitude, force.frequency_hz = "harmonic", 500.0, 5.0
s.model.mesh.element_length_m = 0.025
s.model.mesh.symmetry = "half"
s.simulation.dt_s, s.simulation.t_end_s = 1e-3, 1.0
s.validate()

if len(sys.argv) > 1:
    with open(sys.argv[1], "w") as f:
        f.write(s.to_toml())
r = stackbeam.simulate(s)
print(s.setup.strip())
print("w from %.4g to %.4g mm; friction work %.4g J; energy balance error %.2g J"
      % (1000 * r["w"].min(), 1000 * r["w"].max(), r.summary["energy_j"]["dissipated"],
         r.summary["energy_j"]["balance_error_max_abs"]))
