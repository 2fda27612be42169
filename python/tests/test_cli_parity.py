"""The Python results equal the CLI's for the same scenario: the CSV's
arrays bit for bit, summary.json's entries exactly; Example 1 as `cdyn paper`."""

import json
import shutil

import numpy as np
import pytest

import cdyn
from conftest import ROOT, read_csv

EXAMPLES = ROOT / "examples"


def same_bits(a, b):
    """Equal bit for bit (NaN equal to NaN, -0.0 differing from 0.0)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def check_against_csv(result, csv_path):
    header, rows = read_csv(csv_path)
    assert result.columns == header
    assert same_bits(result.table, rows), f"{csv_path}: Python's table differs from the CSV"


@pytest.mark.parametrize(
    "name",
    [
        "cvsgf_energy.toml",
        "four_bar.toml",
        "theta_energy.toml",
        "double_pendulum.toml",
        "baumgarte.toml",
        # Spatial: bodies in Euler parameters, and a URDF robot found
        # relative to the scenario file.
        "heavy_top.toml",
        "arm_tethered.toml",
    ],
)
def test_run_matches_cli_bit_for_bit(cli, tmp_path, name):
    path = EXAMPLES / name
    out = cli("run", path, "--out", tmp_path)
    assert out.returncode == 0, out.stderr
    result = cdyn.run(cdyn.load(path))
    check_against_csv(result, tmp_path / f"{result.name}.csv")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["cases"] == [result.summary]
    # q and v: the first sample is the (assembled) initial state, the last the end state.
    assert same_bits(result.q[-1], result.summary["q_end"]) and same_bits(result.v[-1], result.summary["v_end"])
    assert result.q.shape == result.v.shape == (result.table.shape[0], len(result.summary["q_end"]))


def test_the_same_scenario_from_text_and_dict_runs_the_same(tmp_path):
    path = EXAMPLES / "cvsgf_energy.toml"
    from_file = cdyn.run(cdyn.load(path))
    from_text = cdyn.run(cdyn.loads(path.read_text()))
    tomllib = pytest.importorskip("tomllib")
    from_dict = cdyn.run(tomllib.loads(path.read_text()))
    for other in (from_text, from_dict):
        assert same_bits(other.table, from_file.table) and same_bits(other.q, from_file.q)


def test_model_by_name_is_the_scenario_it_spells(tmp_path):
    s = cdyn.model("chain", scheme="rk4", h=0.01, t_end=0.5, n=3, every=5)
    text = '[model]\nkind = "chain"\n[model.parameters]\nn = 3\n[integrator]\nscheme = "rk4"\nh = 0.01\nt_end = 0.5\n[output]\nevery = 5\n'
    assert same_bits(cdyn.run(s).table, cdyn.run(cdyn.loads(text)).table)
    assert cdyn.run(s).table.shape[0] == 11


def test_compare_matches_cli(cli, tmp_path):
    src = EXAMPLES / "cvsgf_energy.toml"
    path = tmp_path / "short.toml"
    path.write_text(src.read_text().replace("t_end = 20.0", "t_end = 2.0"))
    assert "t_end = 2.0" in path.read_text()
    out = cli("compare", path, "--out", tmp_path / "out")
    assert out.returncode == 0, out.stderr
    results = cdyn.compare(cdyn.load(path))
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert [c["name"] for c in summary["cases"]] == list(results)
    for case in summary["cases"]:
        assert results[case["name"]].summary == case
        check_against_csv(results[case["name"]], tmp_path / "out" / f"{case['name']}.csv")


def test_example1_matches_cdyn_paper(cli, tmp_path):
    out = cli("paper", "--out", tmp_path)
    assert out.returncode == 0, out.stderr
    results = cdyn.example1()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert [c["name"] for c in summary["cases"]] == list(results)
    for case in summary["cases"]:
        assert results[case["name"]].summary == case
        check_against_csv(results[case["name"]], tmp_path / f"{case['name']}.csv")
    # The paper's point: CVSGF with energy control keeps Φ and Ψ small over t ∈ [0, 20].
    best = results["cvsgf_energy"]
    assert best.t[-1] == 20.0 and np.abs(best.phi).max() < 1e-3 and np.abs(best.psi).max() < 1e-3
    assert np.abs(results["none"].phi).max() > 10 * np.abs(best.phi).max()


SWEEP = """
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
alpha_g = 40.0
energy = "gradient"
alpha_e = 40.0
apply = "forward_euler"
[integrator]
scheme = "ab3"
h = 0.01
t_end = 2.0
[sweep]
alpha_g = [5.0, 40.0, 160.0]
alpha_e = [5.0, 40.0, 160.0]
h = [0.01, 0.005]
"""


def test_sweep_is_the_same_on_1_and_2_threads_and_as_the_cli(cli, tmp_path):
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP)
    scenario = cdyn.load(path)
    one, two = cdyn.sweep(scenario, threads=1), cdyn.sweep(scenario, threads=2)
    assert one.summary == two.summary
    assert len(one.summary["points"]) == 18 and one.values.shape == (18, 3)
    out = cli("sweep", path, "--out", tmp_path / "out", "--quiet", "--threads", "2")
    assert out.returncode == 0, out.stderr
    assert json.loads((tmp_path / "out" / "sweep.json").read_text()) == one.summary
    assert same_bits(one.max_abs_phi, [p["max_abs_phi"] for p in one.summary["points"]])


def test_to_pandas(tmp_path):
    pd = pytest.importorskip("pandas")
    r = cdyn.run(cdyn.model("pendulum", h=0.01, t_end=0.1))
    df = r.to_pandas()
    assert isinstance(df, pd.DataFrame) and list(df.columns[: len(r.columns)]) == r.columns
    assert same_bits(df["phi"].to_numpy(), r.phi)


def test_multipliers_are_the_pendulum_tension():
    # Unit mass, length and gravity; Φ = (X² + Y² − 1)/2, so Φ_q = (X, Y) and
    # M a = G − Φ_qᵀ λ with X·a + |v|² = 0 give λ = (|v|² − g Y) / (X² + Y²).
    r = cdyn.run(cdyn.model("pendulum", scheme="rk4", h=0.01, t_end=2.0), multipliers=True)
    assert r.lam.shape == (r.table.shape[0], 1)
    (x, y), (vx, vy) = r.q.T, r.v.T
    expected = (vx**2 + vy**2 - y) / (x**2 + y**2)
    assert np.allclose(r.lam[:, 0], expected, rtol=1e-12, atol=1e-12)
    assert cdyn.run(cdyn.model("pendulum", h=0.01, t_end=0.1)).lam is None


def test_multipliers_of_a_mechanism_have_one_column_per_constraint():
    r = cdyn.run(cdyn.load(EXAMPLES / "four_bar.toml"), multipliers=True)
    assert r.lam.shape[0] == r.table.shape[0] and r.lam.shape[1] > 0 and np.isfinite(r.lam).all()


def test_numpy_numbers_in_a_dict_and_the_toml_round_trip():
    data = {
        "model": {"kind": "pendulum"},
        "integrator": {"scheme": "rk4", "h": np.float64(0.01), "t_end": np.float32(0.5)},
        "output": {"every": np.int64(5)},
    }
    s = cdyn.from_dict(data)
    r = cdyn.run(s)
    assert r.table.shape[0] == 11 and r.summary["h"] == 0.01
    again = cdyn.loads(s.to_toml())
    assert same_bits(cdyn.run(again).table, r.table)
    assert s.file == "<dict>" and not s.has_sweep and "<dict>" in repr(s)


def without_timings(summary):
    """precision.json without what the clock measured (wall time per
    second, and the cheapest line, which is chosen by it)."""
    summary = json.loads(json.dumps(summary))
    summary.pop("cheapest")
    for line in summary["lines"]:
        for point in line["points"]:
            point.pop("wall_per_second")
    return summary


def test_precision_is_the_clis_precision_json(cli, tmp_path):
    scenario = EXAMPLES / "cvsgf_energy.toml"
    args = ["--schemes", "rk4", "--methods", "none,robust", "--h", "0.02,0.01", "--t-end", "1"]
    out = cli("precision", scenario, "--out", tmp_path, *args)
    assert out.returncode == 0, out.stderr
    result = cdyn.precision(scenario, schemes=["rk4"], methods=["none", "robust"], h=[0.02, 0.01], t_end=1.0)
    written = json.loads((tmp_path / "precision.json").read_text())
    assert without_timings(result.summary) == without_timings(written)
    # The same lines and points as the CLI's CSV, each value but the time.
    assert [line["method"] for line in result.lines] == ["none", "robust"]
    assert all(len(line["points"]) == 2 and line["scheme"] == "rk4" for line in result.lines)
    assert result.reference["kind"] == "closed form"
    csv_cli = (tmp_path / "precision.csv").read_text().splitlines()
    assert result.csv.splitlines()[0] == csv_cli[0] and len(result.csv.splitlines()) == len(csv_cli)
    assert result.table.splitlines()[0] in out.stdout
    with pytest.raises(cdyn.ScenarioError, match="unknown scheme `rk5`"):
        cdyn.precision(scenario, schemes=["rk5"])


def test_suite_is_the_clis_suite_json_and_table(cli, tmp_path):
    extra = EXAMPLES / "suite" / "satellite_planar.toml"
    out = cli("suite", "--light", extra, "--out", tmp_path)
    assert out.returncode == 0, out.stderr
    result = cdyn.suite([extra], light=True)
    written = (tmp_path / "suite.json").read_text()
    assert result.summary == json.loads(written)
    assert result.table in out.stdout
    # Every model, all five schemes and both steps; the misses are the CLI's, named.
    models = {c["model"] for c in result.cases}
    assert "satellite_planar" in models and len(result.cases) == 10 * len(models)
    assert result.misses == json.loads(written)["summary"]["misses"]
    with pytest.raises(cdyn.ScenarioError, match="nothing.toml"):
        cdyn.suite([tmp_path / "nothing.toml"], light=True)
