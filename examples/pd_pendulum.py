"""The PD controller of examples/pd_pendulum.c, written in Python, driving
the pendulum of examples/pd_pendulum.toml three ways — as an FMU
co-simulated by FMPy, through the C API (ctypes) and through the Python
API (cdyn.Simulation) — and the three runs agree to the bit: one library
steps all of them. Every 10 ms the controller reads the link's angle and
sets the torque input ``tau``.

    cargo build -p cdyn-cli -p cdyn-capi
    cdyn fmu examples/pd_pendulum.toml --out pd_pendulum.fmu
    python examples/pd_pendulum.py pd_pendulum.fmu target/debug/libcdyn_capi.so

(python/tests/test_fmu.py runs it in CI; needs fmpy and the cdyn package.)
"""

from __future__ import annotations

import ctypes
import os
import sys
from typing import Callable, List, Tuple

KP, KD, TARGET = 40.0, 6.0, -0.5
DT = 0.01  # the control period: 10 steps of the scenario's h = 1e-3
PERIODS = 200
SCENARIO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "pd_pendulum.toml")


def control(read_angle: Callable[[], float], set_torque: Callable[[float], None], advance: Callable[[], None]) -> List[float]:
    """Runs the discrete PD loop; returns the angle at every control instant."""
    angles, previous = [], 0.0
    for _ in range(PERIODS):
        angle = read_angle()
        angles.append(angle)
        set_torque(KP * (TARGET - angle) - KD * (angle - previous) / DT)
        previous = angle
        advance()
    angles.append(read_angle())
    return angles


def with_fmu(fmu: str) -> List[float]:
    """Co-simulated by FMPy: its FMU2Slave over fmi2DoStep."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(fmu)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="pd")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    clock = [0.0]

    def advance() -> None:
        slave.doStep(currentCommunicationPoint=clock[0], communicationStepSize=DT)
        clock[0] = slave.getReal([vr["t"]])[0]

    angles = control(
        lambda: slave.getReal([vr["link.angle"]])[0], lambda tau: slave.setReal([vr["tau"]], [tau]), advance
    )
    slave.terminate()
    slave.freeInstance()
    return angles


def with_c_api(library: str) -> List[float]:
    """Through the C API of crates/cdyn-capi/include/cdyn.h, by ctypes."""
    lib = ctypes.CDLL(library)
    lib.cdyn_last_error.restype = ctypes.c_char_p
    lib.cdyn_output_name.restype = ctypes.c_char_p
    lib.cdyn_output_count.restype = ctypes.c_size_t
    lib.cdyn_set_input_by_name.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_double]
    lib.cdyn_step.argtypes = [ctypes.c_void_p, ctypes.c_uint64]
    for f in ("cdyn_output_count", "cdyn_output_name", "cdyn_get_outputs", "cdyn_free"):
        getattr(lib, f).argtypes = [ctypes.c_void_p] + {"cdyn_output_name": [ctypes.c_size_t], "cdyn_get_outputs": [ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]}.get(f, [])
    sim = ctypes.c_void_p()
    if lib.cdyn_create_from_file(SCENARIO.encode(), ctypes.byref(sim)) != 0:
        raise RuntimeError(lib.cdyn_last_error().decode())
    n = lib.cdyn_output_count(sim)
    names = [lib.cdyn_output_name(sim, i).decode() for i in range(n)]
    out = (ctypes.c_double * n)()

    def read_angle() -> float:
        lib.cdyn_get_outputs(sim, out, n)
        return out[names.index("link.angle")]

    def check(status: int) -> None:
        if status != 0:
            raise RuntimeError(lib.cdyn_last_error().decode())

    angles = control(read_angle, lambda tau: check(lib.cdyn_set_input_by_name(sim, b"tau", tau)), lambda: check(lib.cdyn_step(sim, 10)))
    lib.cdyn_free(sim)
    return angles


def with_python() -> List[float]:
    """Through cdyn.Simulation."""
    import cdyn

    sim = cdyn.Simulation(SCENARIO)
    return control(lambda: sim.output("link.angle"), lambda tau: sim.set_input("tau", tau), lambda: sim.step(10))


def main(argv: List[str]) -> Tuple[List[float], List[float], List[float]]:
    fmu, library = argv[1], argv[2]
    runs = with_fmu(fmu), with_c_api(library), with_python()
    print(f"angle after {PERIODS * DT:g} s: FMU {runs[0][-1]:.15f}, C API {runs[1][-1]:.15f}, Python {runs[2][-1]:.15f}")
    assert runs[0] == runs[1] == runs[2], "the three runs differ"
    print("the three runs agree to the bit")
    return runs


if __name__ == "__main__":
    main(sys.argv)
