"""A quarter-car with a stackbeam leaf spring, the spring an FMI 2.0 co-simulation FMU (docs/fmu.md).

    stackbeam fmu scenarios/rig_friction.toml --out spring.fmu
    python3 examples/fmu/quarter_car.py spring.fmu

The body (sprung mass, +y up) carries the spring's frame; the axle (unsprung mass) sits in the
spring's seat and on a tyre (a linear spring) over the road, which has a 10 mm step at t = 0.05 s.
The spring's input is the axle's motion relative to the body, w = y_axle - y_body (and its
velocity); its output seat.force_n acts on the axle, and reversed on the body. The masses are
integrated here by velocity Verlet at the FMU's step h; the spring force is read at the new
positions (the FMU's outputs depend directly on its inputs). Prints t, body and axle
displacement [m], spring force [N] and the energy the leaves' friction dissipated [J].
Only ctypes, zipfile and xml.etree: no stackbeam installation needed.
"""
import ctypes
import pathlib
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile

M_BODY_KG, M_AXLE_KG, K_TYRE_N_PER_M = 100.0, 20.0, 2.0e5  # quarter of a light truck's rear, its tyre
STEP_M, T_STEP_S, T_END_S = 0.01, 0.05, 0.5


def main(fmu_path):
    d = pathlib.Path(tempfile.mkdtemp())
    zipfile.ZipFile(fmu_path).extractall(d)
    root = ET.parse(d / "modelDescription.xml").getroot()
    vr = {v.get("name"): int(v.get("valueReference")) for v in root.iter("ScalarVariable")}
    h = float(root.find("DefaultExperiment").get("stepSize"))  # the scenario's dt: one FMU step per step
    lib = ctypes.CDLL(str(d / "binaries" / "linux64" / (root.find("CoSimulation").get("modelIdentifier") + ".so")))
    logger_t = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                                ctypes.c_char_p, ctypes.c_char_p)
    logger = logger_t(lambda env, name, status, cat, fmt, msg: print("fmu:", (msg or b"").decode(), file=sys.stderr))

    class Callbacks(ctypes.Structure):
        _fields_ = [("logger", logger_t), ("allocateMemory", ctypes.c_void_p), ("freeMemory", ctypes.c_void_p),
                    ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]
    callbacks = Callbacks(logger, None, None, None, None)
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                    ctypes.POINTER(Callbacks), ctypes.c_int, ctypes.c_int]
    lib.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    lib.fmi2SetupExperiment.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double, ctypes.c_double,
                                        ctypes.c_int, ctypes.c_double]
    c = ctypes.c_void_p(lib.fmi2Instantiate(b"quarter_car", 1, root.get("guid").encode(),
                                             (d / "resources").as_uri().encode(), ctypes.byref(callbacks), 0, 0))
    assert c.value, "fmi2Instantiate failed"
    assert lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, T_END_S) == 0
    assert lib.fmi2EnterInitializationMode(c) == 0 and lib.fmi2ExitInitializationMode(c) == 0

    ins = (ctypes.c_uint * 2)(vr["seat.displacement_m"], vr["seat.velocity_m_per_s"])
    outs = (ctypes.c_uint * 2)(vr["seat.force_n"], vr["spring.dissipated_energy_j"])
    y = (ctypes.c_double * 2)()

    def spring(w, wd):
        lib.fmi2SetReal(c, ins, 2, (ctypes.c_double * 2)(w, wd))
        assert lib.fmi2GetReal(c, outs, 2, y) == 0, "fmi2GetReal failed"
        return y[0], y[1]

    def accelerations(t, yb, ya, force):
        road = STEP_M if t >= T_STEP_S else 0.0
        return -force / M_BODY_KG, (force + K_TYRE_N_PER_M * (road - ya)) / M_AXLE_KG  # no gravity: about equilibrium

    yb = ya = vb = va = 0.0
    force, dissipated = spring(0.0, 0.0)
    ab, aa = accelerations(0.0, yb, ya, force)
    n = round(T_END_S / h)
    print("t_s,body_m,axle_m,spring_force_n,dissipated_j")
    for i in range(n):
        assert lib.fmi2DoStep(c, i * h, h, 1) == 0, "fmi2DoStep failed"
        t = (i + 1) * h
        yb += h * vb + 0.5 * h * h * ab
        ya += h * va + 0.5 * h * h * aa
        force, dissipated = spring(ya - yb, (va + h * aa) - (vb + h * ab))
        ab1, aa1 = accelerations(t, yb, ya, force)
        vb += 0.5 * h * (ab + ab1)
        va += 0.5 * h * (aa + aa1)
        ab, aa = ab1, aa1
        if (i + 1) % 10 == 0:
            print(f"{t:.4f},{yb:.6e},{ya:.6e},{force:.6e},{dissipated:.6e}")
    lib.fmi2Terminate(c)
    lib.fmi2FreeInstance(c)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "spring.fmu")
