"""cdyn.Simulation: a scenario's case stepped from Python. Its outputs are
the rows `cdyn run` writes (bit for bit); inputs act; the state is read,
written, saved and restored; bad inputs raise cdyn.Error."""

import numpy as np
import pytest

import cdyn
from conftest import ROOT, read_csv

SCENARIO = ROOT / "examples" / "pd_pendulum.toml"


def test_outputs_are_the_rows_cdyn_run_writes(cli, tmp_path):
    assert cli("run", SCENARIO, "--out", tmp_path).returncode == 0
    header, rows = read_csv(tmp_path / "pd_pendulum.csv")
    sim = cdyn.Simulation(SCENARIO)
    assert sim.input_names == ["tau"] and sim.output_names == ["t", "link.angle", "link.x", "link.y", "psi"]
    columns = [header.index(name) for name in sim.output_names]
    for row in rows:
        assert np.array_equal(sim.outputs(), np.array(row)[columns])
        sim.step(10)


def test_inputs_act_and_a_snapshot_repeats_the_run():
    a, b = cdyn.Simulation(SCENARIO), cdyn.Simulation(SCENARIO)
    a.set_input("tau", 3.0)
    a.step(100)
    b.step(100)
    assert a.output("link.angle") > b.output("link.angle") + 1e-3, "inputs are a simulation's own"
    saved = a.snapshot()
    q, v, e = a.state()

    def run(sim):
        out = []
        for k in range(20):
            sim.set_input(0, np.sin(k))
            sim.step(5)
            out.append(sim.outputs())
        return np.array(out)

    first = run(a)
    a.restore(saved)
    assert a.steps == 100 and a.input(0) == 3.0
    assert np.array_equal(run(a), first)
    a.set_state(q, v, e)
    assert all(np.array_equal(x, y) for x, y in zip(a.state()[:2], (q, v)))


def test_bad_inputs_raise_with_the_message():
    sim = cdyn.Simulation(SCENARIO)
    with pytest.raises(cdyn.Error, match=r'input "tau": nan: must be finite|input "tau": NaN: must be finite'):
        sim.set_input("tau", float("nan"))
    with pytest.raises(cdyn.Error, match="no such input; the model has the inputs tau"):
        sim.set_input("torque", 1.0)
    with pytest.raises(cdyn.ScenarioError, match="select: no output"):
        cdyn.Simulation(cdyn.loads(SCENARIO.read_text().replace('"psi"]', '"energy"]')))


LIMITED = ROOT / "examples" / "limited_pendulum.toml"


def test_a_limited_case_steps_as_cdyn_run_runs_it_and_restores_across_its_impact(cli, tmp_path):
    # The rod falls onto its limit at t = 0.335 s and is held there.
    assert cli("run", LIMITED, "--out", tmp_path).returncode == 0
    header, rows = read_csv(tmp_path / "limited_pendulum.csv")
    sim = cdyn.Simulation(LIMITED)
    assert sim.output_names == header
    saved = None
    for k, row in enumerate(rows):
        assert np.array_equal(sim.outputs(), np.array(row)), f"row {k}"
        if k == 30:
            saved = sim.snapshot()
        sim.step(10)
    events = sim.limits["events"]
    assert [(e["event"], e["side"], e["held"]) for e in events] == [("impact", "lower", True)]
    assert abs(events[0]["t"] - 0.33526414955) < 1e-3
    # Restored after the impact to a snapshot from before it: the same rows.
    sim.restore(saved)
    assert sim.steps == 300 and sim.limits["events"] == []
    for k, row in list(enumerate(rows))[30:60]:
        assert np.array_equal(sim.outputs(), np.array(row)), f"row {k} after the restore"
        sim.step(10)
    assert len(sim.limits["events"]) == 1
    assert cdyn.Simulation(SCENARIO).limits is None
