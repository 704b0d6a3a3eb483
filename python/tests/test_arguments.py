"""Every value a user gives the module is checked: None, a bool where a number is wanted, a
string, another object, an int no double holds (10**400) raise a Python exception naming the
attribute or argument (InputTypeError: an InputError and a TypeError; InputError for a value
out of a C++ number's range), never a crash and never a silent conversion (True taken as 1 m).

The systematic probes run in a child interpreter: a segfault there is a failed test (exit
status -11), not a dead pytest."""
import json
import os
import subprocess
import sys

import pytest

import stackbeam

BAD = {"None": None, "True": True, "'x'": "x", "10**400": 10 ** 400, "object()": object(), "[None]": [None]}

# Every attribute with a setter of every class a user reaches, each set to every BAD value;
# every public callable called with a BAD value in each argument slot. Prints one JSON row
# per try: [where, bad, outcome] where outcome is the exception's type name or "accepted".
PROBE = r"""
import json, stackbeam
from stackbeam import _core
BAD = {"None": None, "True": True, "'x'": "x", "10**400": 10 ** 400, "object()": object(), "[None]": [None]}
rows = []

def attempt(where, bad, call):
    try:
        call()
        rows.append([where, bad, "accepted"])
    except Exception as e:
        rows.append([where, bad, type(e).__name__ + ("/InputError" if isinstance(e, stackbeam.InputError) else "")])

s = stackbeam.paper_example("friction")
objects = {
    "Leaf": stackbeam.Leaf(), "LeafProfile": stackbeam.LeafProfile(), "LeafEnd": stackbeam.LeafEnd(),
    "Interface": stackbeam.Interface(), "Clamp": stackbeam.Clamp(), "Clip": stackbeam.Clip(),
    "Probe": stackbeam.Probe(), "TimeFunction": stackbeam.TimeFunction(), "rigid_body": s.model.rigid_body,
    "loading": s.model.loading, "mesh": s.model.mesh, "model": s.model, "outputs": s.outputs, "Scenario": s,
}
for cls_name, obj in objects.items():
    for name in dir(type(obj)):
        attr = getattr(type(obj), name)
        if name.startswith("_") or not isinstance(attr, property) or attr.fset is None:
            continue
        for bad, value in BAD.items():
            attempt(cls_name + "." + name, bad, lambda: setattr(obj, name, value))
for row in stackbeam.option_table():
    *path, last = row["member"].split(".")
    for bad, value in BAD.items():
        def set_option():
            target = s.simulation
            for part in path:
                target = getattr(target, part)
            setattr(target, last, value)
        attempt("simulation." + row["member"], bad, set_option)
        attempt("simulate(" + row["member"] + "=)", bad, lambda: stackbeam.simulate(s, **{row["member"]: value}))

good = {"scenario": s}
calls = {
    "simulate": lambda a: stackbeam.simulate(a),
    "simulate(pairs=)": lambda a: stackbeam.simulate(s, pairs=a, t_end_s=0.01),
    "simulate(nodes=)": lambda a: stackbeam.simulate(s, nodes=a, t_end_s=0.01),
    "make_stepper": lambda a: stackbeam.make_stepper(a),
    "Stepper": lambda a: stackbeam.Stepper(a, {}),
    "Stepper(options)": lambda a: stackbeam.Stepper(s, a),
    "sweep": lambda a: stackbeam.sweep(a),
    "sweep(jobs=)": lambda a: stackbeam.sweep("/nonexistent.toml", jobs=a),
    "sweep(out_dir=)": lambda a: stackbeam.sweep("/nonexistent.toml", out_dir=a),
    "sweep(restart=)": lambda a: stackbeam.sweep("/nonexistent.toml", restart=a),
    "sweep(keep_series=)": lambda a: stackbeam.sweep("/nonexistent.toml", keep_series=a),
    "load_scenario": lambda a: stackbeam.load_scenario(a),
    "paper_example": lambda a: stackbeam.paper_example(a),
    "paper_example(elements_per_half_leaf)": lambda a: stackbeam.paper_example("friction", a),
    "paper_example(full_model)": lambda a: stackbeam.paper_example("friction", 10, a),
    "Probe(interface_index)": lambda a: stackbeam.Probe(a, 0.1),
    "Probe(x_m)": lambda a: stackbeam.Probe(0, a),
    "Scenario.from_toml": lambda a: stackbeam.Scenario.from_toml(a),
    "Scenario.from_toml(source)": lambda a: stackbeam.Scenario.from_toml("", a),
    "_core._run": lambda a: _core._run(a, {}, False, False),
    "_core._run(options)": lambda a: _core._run(s, {a: 1.0} if a.__hash__ else a, False, False),
    "_core._run(pairs)": lambda a: _core._run(s, {"t_end_s": 0.01}, a, False),
    "_core._stack_geometry": lambda a: _core._stack_geometry(a),
    "_core._sweep(jobs)": lambda a: _core._sweep("/nonexistent.toml", a, "", False, False),
    "Scenario.__deepcopy__": lambda a: s.__deepcopy__(a),
    "Stepper.advance(a)": lambda a: stackbeam.make_stepper(s, t_end_s=0.01).advance(a),
}
for where, call in calls.items():
    for bad, value in BAD.items():
        attempt(where, bad, lambda: call(value))
print(json.dumps(rows))
"""


@pytest.fixture(scope="module")
def probed():
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=600, env=os.environ)
    assert done.returncode == 0, "the probe crashed (exit status %d): %s" % (done.returncode, done.stderr[-2000:])
    return json.loads(done.stdout)


def test_every_setter_and_callable_raises_for_bad_values_and_never_crashes(probed):
    assert len(probed) > 500  # every attribute, option and callable tried (about 1,100 tries)
    # accepted on purpose: None for model.probe (no probe) and the seat loads and windup rig (none), a string for the string attributes
    # (the outputs' paths, the description), True for the bool arguments; anything else
    # accepted is a silent conversion
    bools = ("simulate(pairs=)", "simulate(nodes=)", "paper_example(full_model)", "_core._run(pairs)")

    def on_purpose(where, bad):
        optional = ("model.probe", "loading.seat_moment_n_m", "loading.longitudinal_force_n",
                    "loading.seat_rotation_rad")  # None: no probe, no seat load, no windup rig
        return ((where in optional and bad == "None") or (bad == "True" and where in bools) or
                (bad == "'x'" and (where.startswith("outputs.") or where == "Scenario.description")))

    accepted = [(w, b) for w, b, outcome in probed if outcome == "accepted" and not on_purpose(w, b)]
    assert accepted == [], accepted
    # the module's own exceptions (or Python's TypeError from pybind11 for a wrong class), never
    # a bare RuntimeError ("Unable to cast Python instance to C++ type")
    bare = [(w, b, o) for w, b, o in probed if o.startswith("RuntimeError")]
    assert bare == [], bare


def test_setters_name_the_attribute_and_the_value():
    leaf = stackbeam.Leaf()
    with pytest.raises(stackbeam.InputTypeError) as e:
        leaf.height_m = True  # was taken as 1 m
    assert isinstance(e.value, TypeError) and isinstance(e.value, stackbeam.InputError)
    assert e.value.field == "Leaf.height_m" and "True" in str(e.value) and "real number" in str(e.value)
    assert leaf.height_m == 0.0  # unchanged
    with pytest.raises(stackbeam.InputError) as e:
        leaf.height_m = 10 ** 400
    assert e.value.field == "Leaf.height_m" and "double's range" in str(e.value)
    leaf.height_m = 7  # an int is a real number
    assert leaf.height_m == 7.0
    clip = stackbeam.Clip()
    with pytest.raises(stackbeam.InputError) as e:
        clip.first_leaf = 2 ** 40
    assert e.value.field == "Clip.first_leaf" and "integer from" in str(e.value)
    with pytest.raises(stackbeam.InputTypeError):
        clip.first_leaf = 1.0
    with pytest.raises(stackbeam.InputTypeError) as e:
        stackbeam.paper_example("friction").model.loading.kind = None
    assert e.value.field == "loading.kind"


def test_none_to_simulate_and_make_stepper_is_a_type_error():
    for call in (stackbeam.simulate, stackbeam.make_stepper):
        with pytest.raises(TypeError) as e:
            call(None)
        assert e.value.field == "scenario" and "stackbeam.Scenario" in str(e.value)


def test_t_end_beyond_a_double_is_an_input_error_naming_it():
    scenario = stackbeam.paper_example("friction")
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.simulate(scenario, t_end_s=10 ** 400)
    assert e.value.field == "t_end_s" and "10000000000" in str(e.value)
    with pytest.raises(stackbeam.InputTypeError) as e:
        stackbeam.simulate(scenario, t_end_s=True)
    assert e.value.field == "t_end_s"


@pytest.mark.parametrize("mode", ["newmark", "cvode"])
def test_advance_past_t_end_is_refused(mode):
    stepper = stackbeam.make_stepper(stackbeam.paper_example("friction"), mode=mode, t_end_s=0.003, dt_s=0.001)
    records = [stepper.advance() for _ in range(stepper.records - 1)]
    assert stepper.record_index == 3 and records[-1]["t"] == pytest.approx(0.003, abs=1e-12)
    with pytest.raises(stackbeam.InputError) as e:
        stepper.advance()
    assert e.value.field == "advance" and "t_end" in str(e.value)
    assert stepper.record_index == 3  # still at the last record
    assert list(stepper) == []  # iterating from the end yields nothing


def test_huge_jobs_is_refused_before_any_thread(tmp_path):
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.sweep(tmp_path / "none.toml", jobs=10 ** 6)
    assert e.value.field == "jobs" and "1024" in str(e.value)
    with pytest.raises(stackbeam.InputTypeError):
        stackbeam.sweep(tmp_path / "none.toml", jobs=True)
