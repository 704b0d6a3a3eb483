"""The FMU as a Python importer sees it (docs/fmu.md): stackbeam.export_fmu writes it; zipfile
unpacks it into a fresh directory, xml.etree reads modelDescription.xml and ctypes drives the binary
through the FMI 2.0 calls only (no code shared with the exporter or the FMU)."""
import ctypes
import math
import xml.etree.ElementTree as ET
import zipfile

import pytest

import stackbeam

REQUIRED = """fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset fmi2GetReal
fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean fmi2SetString fmi2GetFMUstate
fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize fmi2SerializeFMUstate fmi2DeSerializeFMUstate
fmi2GetDirectionalDerivative fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives fmi2DoStep fmi2CancelStep
fmi2GetStatus fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus fmi2GetStringStatus""".split()

OK, ERROR = 0, 3
CO_SIMULATION = 1

# the standard's callback struct (fmi2CallbackFunctions); the logger is variadic: its fixed
# arguments are read, the message is the format (the FMU passes "%s" and one string argument)
LOGGER = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                          ctypes.c_char_p)
messages = []


@LOGGER
def _logger(env, name, status, category, fmt, arg):
    messages.append((arg or fmt or b"").decode())


class Callbacks(ctypes.Structure):
    _fields_ = [("logger", LOGGER), ("allocateMemory", ctypes.c_void_p), ("freeMemory", ctypes.c_void_p),
                ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]


@pytest.fixture(scope="module")
def fmu(tmp_path_factory, request):
    from conftest import SOURCE_DIR
    d = tmp_path_factory.mktemp("fmu")
    path = d / "spring.fmu"
    stackbeam.export_fmu(str(SOURCE_DIR / "scenarios" / "rig_friction.toml"), str(path))
    with zipfile.ZipFile(path) as z:
        z.extractall(d / "unpacked")
    root = ET.parse(d / "unpacked" / "modelDescription.xml").getroot()
    ident = root.find("CoSimulation").get("modelIdentifier")
    lib = ctypes.CDLL(str(d / "unpacked" / "binaries" / "linux64" / (ident + ".so")))
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                    ctypes.POINTER(Callbacks), ctypes.c_int, ctypes.c_int]
    for f in REQUIRED:
        if f not in ("fmi2Instantiate", "fmi2GetVersion", "fmi2GetTypesPlatform", "fmi2FreeInstance"):
            getattr(lib, f).restype = ctypes.c_int
    lib.fmi2GetVersion.restype = ctypes.c_char_p
    lib.fmi2GetTypesPlatform.restype = ctypes.c_char_p
    lib.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
    lib.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    lib.fmi2SetupExperiment.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double, ctypes.c_double,
                                        ctypes.c_int, ctypes.c_double]
    for f in ("fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset"):
        getattr(lib, f).argtypes = [ctypes.c_void_p]
    state_p = ctypes.POINTER(ctypes.c_void_p)
    lib.fmi2GetFMUstate.argtypes = [ctypes.c_void_p, state_p]
    lib.fmi2SetFMUstate.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    lib.fmi2FreeFMUstate.argtypes = [ctypes.c_void_p, state_p]
    lib.fmi2SerializedFMUstateSize.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(ctypes.c_size_t)]
    lib.fmi2SerializeFMUstate.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t]
    lib.fmi2DeSerializeFMUstate.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, state_p]
    variables = {v.get("name"): v for v in root.iter("ScalarVariable")}
    callbacks = Callbacks(_logger, None, None, None, None)
    uri = (d / "unpacked" / "resources").as_uri().encode()

    class F:
        pass
    f = F()
    f.lib, f.root, f.variables, f.callbacks, f.uri = lib, root, variables, callbacks, uri
    f.guid = root.get("guid").encode()
    f.dir = d
    return f


def instantiate(f, name=b"py"):
    c = f.lib.fmi2Instantiate(name, CO_SIMULATION, f.guid, f.uri, ctypes.byref(f.callbacks), 0, 0)
    assert c
    return ctypes.c_void_p(c)


def vr(f, name):
    return int(f.variables[name].get("valueReference"))


def get(f, c, names):
    refs = (ctypes.c_uint * len(names))(*[vr(f, n) for n in names])
    out = (ctypes.c_double * len(names))()
    status = f.lib.fmi2GetReal(c, refs, ctypes.c_size_t(len(names)), out)
    return status, list(out)


def set_(f, c, names, values):
    refs = (ctypes.c_uint * len(names))(*[vr(f, n) for n in names])
    vals = (ctypes.c_double * len(names))(*values)
    return f.lib.fmi2SetReal(c, refs, ctypes.c_size_t(len(names)), vals)


def test_every_required_function_is_exported(fmu):
    for name in REQUIRED:
        assert hasattr(fmu.lib, name), name
    assert fmu.lib.fmi2GetVersion() == b"2.0"
    assert fmu.root.get("fmiVersion") == "2.0"


def test_the_xml_variables_answer_the_calls(fmu):
    c = instantiate(fmu)
    assert fmu.lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) == OK
    assert fmu.lib.fmi2EnterInitializationMode(c) == OK
    for name, v in fmu.variables.items():
        real = v.find("Real")
        assert real.get("unit"), name
        status, (x,) = get(fmu, c, [name])
        assert status == OK, (name, messages[-1:])
        if real.get("start") is not None:
            assert x == float(real.get("start")), name
    assert {v.get("causality") for v in fmu.variables.values()} == {"input", "output", "parameter"}
    fmu.lib.fmi2FreeInstance(c)


def test_calls_out_of_order_are_refused(fmu):
    c = instantiate(fmu)
    assert fmu.lib.fmi2DoStep(c, 0.0, 1e-3, 1) == ERROR
    assert "not allowed in state" in messages[-1]
    assert fmu.lib.fmi2ExitInitializationMode(c) == ERROR
    assert get(fmu, c, ["seat.force_n"])[0] == ERROR
    assert set_(fmu, c, ["clamps[0].preload_n"], [-1.0]) == ERROR
    assert "preload_n" in messages[-1] and "-1" in messages[-1]
    assert fmu.lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) == OK
    assert fmu.lib.fmi2EnterInitializationMode(c) == OK
    assert fmu.lib.fmi2ExitInitializationMode(c) == OK
    assert set_(fmu, c, ["integrator.dt_s"], [2e-3]) == ERROR  # fixed after initialisation
    assert fmu.lib.fmi2DoStep(c, 0.0, 0.7e-3, 1) == ERROR      # not a whole number of dt
    assert fmu.lib.fmi2Terminate(c) == OK
    assert fmu.lib.fmi2DoStep(c, 0.0, 1e-3, 1) == ERROR
    assert fmu.lib.fmi2Reset(c) == OK
    assert fmu.lib.fmi2EnterInitializationMode(c) == OK
    fmu.lib.fmi2FreeInstance(c)
    assert fmu.lib.fmi2Instantiate(b"x", CO_SIMULATION, b"{not-it}", fmu.uri, ctypes.byref(fmu.callbacks), 0, 0) is None


def test_a_rig_stroke_through_the_fmu_is_simulate(fmu):
    """The rig stroke at the scenario's step equals stackbeam.simulate of the rig scenario bit for bit
    (the same stepper and the same seat displacement at every record time: tests/fmu/test_fmu.cpp)."""
    from conftest import SOURCE_DIR
    sc = stackbeam.load_scenario(str(SOURCE_DIR / "scenarios" / "rig_friction.toml"))
    result = stackbeam.simulate(sc, t_end_s=0.3)
    t, w, wd = result["t"], result["w"], result["w_dot"]
    force, dissipated = result["spring_force"], result["dissipated_energy"]
    c = instantiate(fmu)
    assert fmu.lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) == OK
    assert fmu.lib.fmi2EnterInitializationMode(c) == OK
    assert fmu.lib.fmi2ExitInitializationMode(c) == OK
    dt = sc.simulation.dt_s
    inputs = ["seat.displacement_m", "seat.velocity_m_per_s"]
    for i in range(len(t)):
        if i > 0:
            assert fmu.lib.fmi2DoStep(c, (i - 1) * dt, dt, 1) == OK, messages[-1:]
        # the records' own w and w' (the triangle's values at the record times, as the stepper took them)
        assert set_(fmu, c, inputs, [w[i], wd[i]]) == OK
        status, (f_seat, e) = get(fmu, c, ["seat.force_n", "spring.dissipated_energy_j"])
        assert status == OK
        assert f_seat == -force[i] and e == dissipated[i], i
    assert dissipated[-1] > 0.0
    fmu.lib.fmi2FreeInstance(c)


def _drive(f, c, w, start, n, dt):
    """n communication steps of dt from record `start`, the seat at w[i]; the force and dissipated energy."""
    out = []
    for i in range(start, start + n):
        assert f.lib.fmi2DoStep(c, ctypes.c_double(i * dt), ctypes.c_double(dt), 1) == OK, messages[-1:]
        assert set_(f, c, ["seat.displacement_m"], [w[i + 1]]) == OK
        status, y = get(f, c, ["seat.force_n", "spring.dissipated_energy_j"])
        assert status == OK
        out.extend(y)
    return out


def _started(f, name=b"py"):
    c = instantiate(f, name)
    assert f.lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) == OK
    assert f.lib.fmi2EnterInitializationMode(c) == OK
    assert f.lib.fmi2ExitInitializationMode(c) == OK
    return c


def _stroke(n, dt, scale=1.0):
    """The rig's triangle: +-20 mm at 1 Hz (scenarios/rig_friction.toml), at the records' times."""
    def tri(t):
        x = (t + 0.25) % 1.0
        return 0.02 * (4.0 * x - 1.0 if x < 0.5 else 3.0 - 4.0 * x)
    return [scale * tri(i * dt) for i in range(n + 1)]


def test_restoring_a_state_repeats_the_outputs_bit_for_bit(fmu):
    """fmi2GetFMUstate / fmi2SetFMUstate and their serialisation from ctypes: on from a saved state,
    elsewhere, back to it (directly and through the bytes): the outputs repeat bit for bit (the FMU
    replays the inputs' history: the same operations on the same doubles)."""
    dt = 1e-3
    w, w_half = _stroke(400, dt), _stroke(400, dt, 0.5)
    c = _started(fmu)
    _drive(fmu, c, w, 0, 100, dt)
    state = ctypes.c_void_p()
    assert fmu.lib.fmi2GetFMUstate(c, ctypes.byref(state)) == OK
    size = ctypes.c_size_t()
    assert fmu.lib.fmi2SerializedFMUstateSize(c, state, ctypes.byref(size)) == OK
    buf = ctypes.create_string_buffer(size.value)
    assert fmu.lib.fmi2SerializeFMUstate(c, state, buf, size) == OK
    copy = ctypes.c_void_p()
    assert fmu.lib.fmi2DeSerializeFMUstate(c, buf, size, ctypes.byref(copy)) == OK
    assert fmu.lib.fmi2DeSerializeFMUstate(c, buf, ctypes.c_size_t(size.value // 2), ctypes.byref(copy)) == ERROR
    first = _drive(fmu, c, w, 100, 150, dt)
    _drive(fmu, c, w_half, 250, 100, dt)  # on elsewhere
    assert fmu.lib.fmi2SetFMUstate(c, state) == OK
    assert _drive(fmu, c, w, 100, 150, dt) == first
    assert fmu.lib.fmi2SetFMUstate(c, copy) == OK
    assert _drive(fmu, c, w, 100, 150, dt) == first
    assert first[-1] > 0.0  # friction worked: not a comparison of zeros
    for s in (state, copy):
        assert fmu.lib.fmi2FreeFMUstate(c, ctypes.byref(s)) == OK
        assert not s.value
    fmu.lib.fmi2FreeInstance(c)


def test_two_instances_on_two_threads_give_the_outputs_of_one_after_the_other(fmu):
    """Several instances in one process, each on its own thread (ctypes releases the GIL during each
    call): the outputs of each equal those of the same run alone."""
    import threading
    dt = 2e-3
    strokes = {b"a": _stroke(151, dt), b"b": _stroke(151, dt, 0.5)}

    def run(name):
        c = _started(fmu, name)
        y = _drive(fmu, c, strokes[name[-1:]], 0, 150, dt)
        fmu.lib.fmi2FreeInstance(c)
        return y
    alone = {k: run(k) for k in strokes}
    results = {}
    threads = [threading.Thread(target=lambda k=k: results.__setitem__(k, run(b"t" + k))) for k in strokes]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == alone
    assert alone[b"a"] != alone[b"b"]
