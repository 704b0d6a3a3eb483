"""The Python API: scenarios (file, paper example, TOML text, built from objects), the model's
attributes named as the scenario keys and validated, the options by member name and the
option table, the Result, the stepper."""
import math
import tomllib

import numpy as np
import pytest

import stackbeam


def same_records(a, b):
    assert list(a) == list(b)
    for name in a:
        np.testing.assert_array_equal(a[name], b[name])


def short(scenario, steps=30):
    return stackbeam.simulate(scenario, t_end_s=steps * scenario.simulation.dt_s)


# --- scenarios and their round trip ---------------------------------------------------------

def test_round_trip_file_python_toml_run(scenarios, tmp_path):
    """file -> Python -> TOML -> run gives the same run (records and summary but wall time)."""
    for name in ["paper_friction.toml", "rig_friction.toml", "base_steel_elastic.toml"]:
        s = stackbeam.load_scenario(str(scenarios / name))
        text = s.to_toml()
        back = stackbeam.Scenario.from_toml(text, source=str(scenarios / name))
        assert back.to_toml() == text
        a, b = short(s), short(back)
        same_records(a, b)
        for r in (a, b):
            r.summary.pop("wall_time_s")
        assert a.summary == b.summary


def test_round_trip_after_python_changes(scenarios):
    s = stackbeam.load_scenario(str(scenarios / "paper_friction.toml"))
    s.model.leaves[0].height_m = 0.006
    s.model.interfaces[1].friction_coefficient = 0.3
    s.model.loading.initial_velocity_m_per_s = 1.5
    s.simulation.solver.tolerance_m = 1e-8
    back = stackbeam.Scenario.from_toml(s.to_toml())
    assert back.model.leaves[0].height_m == 0.006
    assert back.model.interfaces[1].friction_coefficient == 0.3
    assert back.model.loading.initial_velocity_m_per_s == 1.5
    assert back.simulation.solver.tolerance_m == 1e-8
    same_records(short(s), short(back))


def test_paper_example_is_the_papers_file(scenarios):
    """paper_example("friction") and scenarios/paper_friction.toml give the same run."""
    a = short(stackbeam.paper_example("friction"))
    b = short(stackbeam.load_scenario(str(scenarios / "paper_friction.toml")))
    np.testing.assert_allclose(a["w"], b["w"], rtol=0, atol=1e-12)


# --- every attribute reachable: the file's key paths ----------------------------------------

def walk(table, path=""):
    """(key path, value) of every leaf value of a TOML document."""
    for key, value in table.items():
        p = path + ("." if path else "") + key
        if isinstance(value, dict):
            yield from walk(value, p)
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for i, item in enumerate(value):
                yield from walk(item, "%s[%d]" % (p, i))
        else:
            yield p, value


def attribute(scenario, path):
    """The attribute of `scenario` for a file key path: integrator.X -> simulation.X, outputs.X,
    description; the rest under model."""
    head, _, rest = path.partition(".")
    if head == "integrator":
        obj, path = scenario.simulation, rest
    elif head in ("outputs", "description"):
        obj = scenario
    else:
        obj = scenario.model
    for part in path.split("."):
        name, _, index = part.partition("[")
        obj = getattr(obj, name)
        if index:
            obj = obj[int(index[:-1])]
    return obj


def test_every_key_of_every_scenario_file_is_an_attribute(scenarios):
    """Every key written in scenarios/*.toml is reachable under its own path and reads its value
    (the interfaces' law 'frictionless' reads as coulomb with mu = 0)."""
    count = 0
    for path in sorted(scenarios.glob("*.toml")):
        s = stackbeam.load_scenario(str(path))
        with open(path, "rb") as f:
            doc = tomllib.load(f)
        for key, value in walk(doc):
            got = attribute(s, key)
            if key.endswith(".law") and value == "frictionless":
                assert got == "coulomb"
            elif isinstance(value, float) and math.isnan(value):
                assert math.isnan(got)
            else:
                assert (list(got) if isinstance(value, list) else got) == value, (path.name, key)
            count += 1
    assert count > 300


# Every attribute set to a bad value: the error names the scenario key (model) or the member (options).
BAD_VALUES = [
    ("leaves[0].length_m", -1.0), ("leaves[0].height_m", 0.0), ("leaves[0].width_m", -0.05),
    ("leaves[0].youngs_modulus_pa", 0.0), ("leaves[0].density_kg_per_m3", -1.0), ("leaves[0].poisson_ratio", 0.6),
    ("leaves[0].free_camber_m", 1.0), ("leaves[0].free_radius_m", 0.1), ("leaves[0].x_start_m", float("nan")),
    ("leaves[0].left_end.bushing_x_n_per_m", -1.0), ("leaves[0].left_end.shackle_angle_rad", 2.0),
    ("interfaces[0].friction_coefficient", -0.1), ("interfaces[0].initial_gap_m", float("inf")),
    ("interfaces[0].normal_stiffness_pa_per_m", -1.0), ("interfaces[0].tangential_stiffness_pa_per_m", -1.0),
    ("clamps[0].preload_n", -5.0), ("clamps[0].length_m", -0.01), ("clamps[0].x_m", 0.7),
    ("rigid_body.mass_kg", 0.0), ("rigid_body.x_m", 0.9),
    ("loading.initial_velocity_m_per_s", float("nan")), ("loading.gravity_m_per_s2", -9.81),
    ("mesh.element_length_m", 0.0),
]


def set_path(scenario, path, value):
    parent, _, name = path.rpartition(".")
    setattr(attribute(scenario, parent) if parent else scenario.model, name, value)


@pytest.mark.parametrize("key,value", BAD_VALUES)
def test_bad_model_value_raises_input_error_naming_the_key(key, value):
    s = stackbeam.paper_example("friction")
    set_path(s, key, value)
    with pytest.raises(stackbeam.InputError) as e:
        s.validate()
    assert e.value.field == key
    with pytest.raises(stackbeam.InputError):
        stackbeam.simulate(s)


@pytest.mark.parametrize("key,value", [("leaves[0].left_support", "glued"), ("interfaces[0].law", "sticky"),
                                       ("interfaces[0].contact", "soft"), ("loading.kind", "shaking"),
                                       ("mesh.symmetry", "quarter")])
def test_bad_keyword_raises_input_error_naming_the_key(key, value):
    s = stackbeam.paper_example("friction")
    with pytest.raises(stackbeam.InputError) as e:
        set_path(s, key, value)
    assert e.value.field.split(".")[-1] == key.split(".")[-1]
    assert value in str(e.value)


def test_clip_probe_and_time_function_values_are_checked():
    s = stackbeam.paper_example("friction")
    s.model.clips.append(stackbeam.Clip())
    s.model.clips[0].x_m, s.model.clips[0].first_leaf, s.model.clips[0].last_leaf = 0.05, 0, 2
    s.model.clips[0].clearance_m = -1e-3
    with pytest.raises(stackbeam.InputError) as e:
        s.validate()
    assert e.value.field == "clips[0].clearance_m"
    s = stackbeam.paper_example("friction")
    s.model.probe = stackbeam.Probe(interface_index=7, x_m=0.1)
    with pytest.raises(stackbeam.InputError) as e:
        s.validate()
    assert e.value.field.startswith("probe")
    s = stackbeam.paper_example("friction")
    s.model.loading.kind = "applied-force"
    s.model.loading.force_n.shape = "harmonic"
    s.model.loading.force_n.amplitude = 100.0
    s.model.loading.force_n.frequency_hz = -2.0
    with pytest.raises(stackbeam.InputError) as e:
        s.validate()
    assert e.value.field == "loading.force_n.frequency_hz"


def test_error_from_a_file_names_its_line(tmp_path, scenarios):
    text = (scenarios / "paper_friction.toml").read_text().replace("mass_kg = 20.0", "mass_kg = -20.0")
    with pytest.raises(stackbeam.InputError) as e:
        stackbeam.Scenario.from_toml(text, source="mine.toml")
    assert e.value.field == "rigid_body.mass_kg"
    assert e.value.location.startswith("mine.toml:")
    assert isinstance(e.value, ValueError)


# --- options: member names, the option table ------------------------------------------------

def test_every_option_of_the_table_is_an_attribute_and_checked():
    s = stackbeam.paper_example("friction")
    for row in stackbeam.option_table():
        member = row["member"]
        obj = s.simulation
        *parents, name = member.split(".")
        for p in parents:
            obj = getattr(obj, p)
        value = getattr(obj, name)
        setattr(obj, name, value)  # the value read is allowed
        bad = "no-such-word" if isinstance(value, str) else float("nan")
        with pytest.raises(stackbeam.InputError) as e:
            setattr(obj, name, bad)
        assert e.value.field == member
        assert getattr(obj, name) == value  # a refused value leaves the option as it was


def test_simulate_options_by_member_name():
    s = stackbeam.paper_example("friction")
    r = stackbeam.simulate(s, t_end_s=0.05, solver={"tolerance_m": 1e-7})
    assert r["t"][-1] == pytest.approx(0.05)
    assert r.options == {"t_end_s": 0.05, "solver.tolerance_m": 1e-7}
    assert s.simulation.t_end_s == 0.6  # the scenario is not changed
    for bad, field in [({"t_end_s": -1.0}, "t_end_s"), ({"mode": "euler"}, "mode"), ({"cvode": {"rtol": 2.0}}, "cvode.rtol"),
                       ({"no_such_option": 1}, "no_such_option"), ({"dt_s": "fast"}, "dt_s")]:
        with pytest.raises(stackbeam.InputError) as e:
            stackbeam.simulate(s, **bad)
        assert e.value.field == field


def test_solver_error_carries_its_diagnostics():
    s = stackbeam.paper_example("friction")
    with pytest.raises(stackbeam.SolverError) as e:
        stackbeam.simulate(s, t_end_s=0.05, solver={"kind": "paper", "max_iterations": 1})
    assert e.value.step >= 1 and e.value.residual > 0
    assert isinstance(e.value, RuntimeError)


# --- the result -----------------------------------------------------------------------------

def test_result_mapping_summary_pairs_events():
    s = stackbeam.paper_example("friction")
    r = stackbeam.simulate(s, t_end_s=0.05, pairs=True)
    assert list(r) == stackbeam.step_record_columns()
    assert len(r["t"]) == 51 and r["w"].dtype == np.float64
    assert r.events is None  # mode closed-form has no event log
    n_pairs = len(r.pairs["t"]) // 51
    assert set(np.unique(r.pairs["state"])) <= {"stick", "slip", "open"}
    assert len(r.pairs["p_t"]) == 51 * n_pairs
    assert r.summary["mode"] == "closed-form" and r.summary["counts"]["records"] == 51
    assert r.summary["final"]["w_m"] == r["w"][-1]
    c = stackbeam.simulate(s, t_end_s=0.05, mode="cvode")
    assert len(c.events["t"]) > 0 and c.summary["cvode"]["steps"] > 0


def test_to_pandas():
    pandas = pytest.importorskip("pandas")
    r = short(stackbeam.paper_example("bonded"), 5)
    df = r.to_pandas()
    assert isinstance(df, pandas.DataFrame) and list(df.columns) == list(r)


# --- a spring built from Python objects; the stepper ----------------------------------------

def built_spring():
    s = stackbeam.Scenario()
    for _ in range(2):
        leaf = stackbeam.Leaf()
        leaf.length_m, leaf.height_m, leaf.width_m, leaf.youngs_modulus_pa = 0.5, 0.005, 0.05, 2e10
        leaf.left_support = leaf.right_support = "pinned"
        s.model.leaves.append(leaf)
    s.model.interfaces.append(stackbeam.Interface())
    s.model.interfaces[0].friction_coefficient = 0.3
    s.model.rigid_body.mass_kg, s.model.rigid_body.x_m = 10.0, 0.25
    s.model.loading.initial_velocity_m_per_s = 1.0
    s.model.mesh.element_length_m = 0.025
    s.simulation.t_end_s = 0.05
    return s


def test_built_spring_runs_and_is_a_two_leaf_beam():
    """Two frictional leaves, no clamp: the first quarter period's stiffness is between the
    frictionless stack's (2 x 48 E I / L^3) and the bonded beam's (8 x 48 E I / L^3)."""
    s = built_spring()
    s.validate()
    r = stackbeam.simulate(s)
    ei = 2e10 * 0.05 * 0.005 ** 3 / 12
    k_free, k_bonded = 2 * 48 * ei / 0.5 ** 3, 8 * 48 * ei / 0.5 ** 3
    w_max = r["w"].max()  # v0 / omega of the stack, omega = sqrt(k / m)
    assert 1.0 / math.sqrt(k_bonded / 10.0) < w_max < 1.0 / math.sqrt(k_free / 10.0) * 1.001
    text = s.to_toml()
    assert "[[leaves]]" in text and stackbeam.Scenario.from_toml(text).to_toml() == text


def test_stepper_equals_simulate():
    s = stackbeam.paper_example("friction")
    r = stackbeam.simulate(s, t_end_s=0.03)
    stepper = stackbeam.make_stepper(s, t_end_s=0.03)
    assert stepper.records == 31 and stepper.record_index == 0
    records = [stepper.current] + list(stepper)
    assert stepper.record_index == 30
    for name in r:
        np.testing.assert_array_equal([rec[name] for rec in records], r[name])
    pairs = stepper.pairs()
    assert len(pairs["p_n"]) == len(pairs["state"]) > 0
    assert stepper.report()["steps"] == 30


def test_entries_are_shared_objects_and_copies_independent():
    """An entry taken out of a list stays the scenario's entry when the list grows (no dangling
    reference), a copy shares nothing, and None in a list is refused by name."""
    s = stackbeam.paper_example("friction")
    leaf = s.model.leaves[0]
    for _ in range(100):
        s.model.leaves.append(stackbeam.Leaf())
    leaf.height_m = 0.007
    assert s.model.leaves[0].height_m == 0.007
    del s.model.leaves[3:]
    c = s.copy()
    c.model.leaves[0].height_m = 0.001
    c.model.probe.x_m = 0.2
    assert s.model.leaves[0].height_m == 0.007 and s.model.probe.x_m != 0.2
    s.model.clamps.append(None)
    with pytest.raises(stackbeam.InputError) as e:
        s.validate()
    assert e.value.field == "clamps[4]"
