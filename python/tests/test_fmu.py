"""The FMU of `cdyn fmu`, imported by FMPy (a real importer, pinned in
requirements-test.txt): its model description validates with no problems,
FMPy's simulation equals `cdyn run` to the bit (also with joint limits, on
examples/limited_pendulum.toml in body and in joint coordinates), the Python PD controller of
examples/pd_pendulum.py gives the same run through the FMU, the C API and
the Python API (and examples/pd_pendulum.c ends where they do), and
refused calls are fmi2Error with a logged line."""

import importlib.util
import os
import pathlib
import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import ROOT, read_csv

fmpy = pytest.importorskip("fmpy")
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402

SCENARIO = ROOT / "examples" / "pd_pendulum.toml"


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    """pd_pendulum.fmu, written by the cdyn binary with the library beside it."""
    binary = os.environ["CDYN_BIN"]
    out = tmp_path_factory.mktemp("fmu") / "pd_pendulum.fmu"
    done = subprocess.run([binary, "fmu", SCENARIO, "--out", out], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out


def library():
    return str(pathlib.Path(os.environ["CDYN_BIN"]).parent / "libcdyn_capi.so")


def test_fmpy_validates_the_model_description(fmu):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(fmu)) == []


def test_fmpy_simulation_equals_cdyn_run(fmu, cli, tmp_path):
    assert cli("run", SCENARIO, "--out", tmp_path).returncode == 0
    header, rows = read_csv(tmp_path / "pd_pendulum.csv")
    result = fmpy.simulate_fmu(str(fmu), step_size=0.001, output_interval=0.01, stop_time=2.0)
    assert len(result) == len(rows)
    # One library computes both, so they agree to the bit (1e-12 was the requirement).
    for name in ["t", "link.angle", "link.x", "link.y", "psi"]:
        expected = np.array([r[header.index(name)] for r in rows])
        assert np.array_equal(result[name], expected), (name, np.max(np.abs(result[name] - expected)))


LIMITED = ROOT / "examples" / "limited_pendulum.toml"


@pytest.mark.parametrize("coordinates", ["bodies", "joints"])
def test_fmpy_simulation_with_joint_limits_equals_cdyn_run(cli, tmp_path, coordinates):
    """examples/limited_pendulum.toml, in body and in joint coordinates: the
    rod falls onto its limit at t = 0.335 s and is held there; every output
    of the FMU at each communication step (10 steps of h) is `cdyn run`'s
    row to the bit, the impact's segment and the held one's included."""
    scenario = tmp_path / "limited_pendulum.toml"
    text = LIMITED.read_text().replace('kind = "spatial"', f'kind = "spatial"\ncoordinates = "{coordinates}"', 1)
    scenario.write_text(text)
    fmu = tmp_path / "limited_pendulum.fmu"
    done = subprocess.run([os.environ["CDYN_BIN"], "fmu", scenario, "--out", fmu], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert cli("run", scenario, "--out", tmp_path).returncode == 0
    header, rows = read_csv(tmp_path / "limited_pendulum.csv")
    result = fmpy.simulate_fmu(str(fmu), step_size=0.001, output_interval=0.01, stop_time=1.0)
    assert len(result) == len(rows) == 101
    names = [n for n in header if n in result.dtype.names]
    assert {"t", "rod.x", "rod.e2", "joints[0].q", "joints[0].v"} <= set(names), result.dtype.names
    for name in names:
        expected = np.array([r[header.index(name)] for r in rows])
        assert np.array_equal(result[name], expected), (name, np.max(np.abs(result[name] - expected)))
    # Held at its lower bound −0.9 from the step after the impact on.
    q = result["joints[0].q"]
    assert q.min() > -0.9 - 1e-9 and abs(q[-1] + 0.9) < 1e-9, (q.min(), q[-1])


@pytest.fixture(scope="module")
def example():
    """examples/pd_pendulum.py as a module."""
    spec = importlib.util.spec_from_file_location("pd_pendulum", ROOT / "examples" / "pd_pendulum.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_pd_controller_runs_alike_through_the_fmu_the_c_api_and_python(fmu, example):
    through_fmu, through_c, through_python = example.main(["pd_pendulum.py", str(fmu), library()])
    assert through_fmu == through_c == through_python
    assert abs(through_fmu[-1] - example.TARGET) < 0.2, "the controller holds the link near its target"


def test_the_c_example_ends_where_the_python_controller_does(example, tmp_path):
    """examples/pd_pendulum.c, the same controller in C, compiled by gcc:
    its angle at t = 2 s (printed with 17 digits) is the Python runs' to the bit."""
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("no gcc")
    lib = pathlib.Path(library()).parent
    exe = tmp_path / "pd_pendulum"
    include = ROOT / "crates" / "cdyn-capi" / "include"
    source = ROOT / "examples" / "pd_pendulum.c"
    subprocess.run([gcc, "-std=c99", source, f"-I{include}", f"-L{lib}", "-lcdyn_capi", "-lm", "-o", exe], check=True)
    env = {**os.environ, "LD_LIBRARY_PATH": str(lib)}
    out = subprocess.run([exe, SCENARIO], env=env, capture_output=True, text=True, check=True).stdout
    angle = float(re.search(r"t = 2\.000 s: angle (\S+) rad \(target", out).group(1))
    assert angle == example.with_python()[-1], out


class Logged:
    """An FMU2Slave whose log messages are kept."""

    def __init__(self, fmu, guid=None):
        from fmpy import extract, read_model_description
        from fmpy.logging import addLoggerProxy
        from ctypes import byref

        md = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.messages = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: self.messages.append((status, message.decode())))
        addLoggerProxy(byref(self.callbacks))
        self.dir = extract(str(fmu))
        self.slave = FMU2Slave(guid=guid or md.guid, unzipDirectory=self.dir, modelIdentifier="pd_pendulum", instanceName="pd")

    def start(self):
        self.slave.instantiate(callbacks=self.callbacks)
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()
        return self.slave


def test_refused_calls_are_errors_with_one_logged_line(fmu):
    f = Logged(fmu)
    s = f.start()
    for call, message in [
        (lambda: s.doStep(0.0, 0.0015), "communication step 0.0015 is not a whole number of the scenario's steps h = 0.001"),
        (lambda: s.setReal([f.vr["tau"]], [float("nan")]), "tau = NaN: must be finite"),
        (lambda: s.getReal([999]), "no Real variable has value reference 999"),
    ]:
        with pytest.raises(FMICallException, match="status 3"):
            call()
        assert f.messages[-1][0] == 3 and f.messages[-1][1].startswith(message), f.messages[-1]
        assert "\n" not in f.messages[-1][1]
    s.doStep(0.0, 0.01)
    assert s.getReal([f.vr["t"]]) == [0.01]
    s.terminate()
    s.freeInstance()


def test_a_missing_resource_is_logged_and_gives_no_instance(fmu):
    f = Logged(fmu)
    os.remove(os.path.join(f.dir, "resources", "scenario.toml"))
    with pytest.raises(Exception, match="Failed to instantiate"):
        f.start()
    assert "cannot read" in f.messages[-1][1]


def test_two_instances_stay_apart_and_a_state_repeats_the_run(fmu):
    a, b = Logged(fmu), Logged(fmu)
    sa, sb = a.start(), b.start()
    sa.setReal([a.vr["tau"]], [4.0])
    for k in range(10):
        sa.doStep(k * 0.01, 0.01)
        sb.doStep(k * 0.01, 0.01)
    angle = lambda f, s: s.getReal([f.vr["link.angle"]])[0]
    assert angle(a, sa) > angle(b, sb) + 1e-3
    state = sa.getFMUstate()

    def run():
        out = []
        for k in range(10, 20):
            sa.setReal([a.vr["tau"]], [np.cos(k)])
            sa.doStep(k * 0.01, 0.01)
            out.append(angle(a, sa))
        return out

    first = run()
    sa.setFMUstate(state)
    assert run() == first
    sa.freeFMUstate(state)
