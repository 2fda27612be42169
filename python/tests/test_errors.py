"""Bad input raises a cdyn.Error with the CLI's one-line message (the bad-input
classes of crates/cdyn-cli/tests/errors.rs), never a crash of the interpreter."""

import pytest

import cdyn

GOOD = """
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
zeta = 20.0
[integrator]
scheme = "ab3"
h = 0.01
t_end = 1.0
"""


def method(keys):
    return GOOD.replace('geometric = "cvsgf"\nzeta = 20.0', keys)


def velocity(alpha_v):
    return method(f'geometric = "cvsgf"\nzeta = 20.0\nvelocity = "gradient"\n{alpha_v}')


BAD = [
    "",
    "[model\nkind=",
    GOOD.replace('kind = "pendulum"', 'kind = "pendulumm"'),
    GOOD.replace("t_end = 1.0", "t_end = 1.0\nsteps = 3"),
    GOOD.replace("h = 0.01", "h = 0.0"),
    GOOD.replace("h = 0.01", "h = -0.01"),
    GOOD.replace("h = 0.01", "h = nan"),
    GOOD.replace("t_end = 1.0", "t_end = inf"),
    GOOD.replace("zeta = 20.0", "zeta = -1.0"),
    GOOD.replace("zeta = 20.0", "zeta = 1.0\nalpha_g = 3.0"),
    GOOD.replace("zeta = 20.0", "zeta = 1.0\neta = 3.0"),
    GOOD.replace('geometric = "cvsgf"', 'geometric = "magic"'),
    GOOD.replace('scheme = "ab3"', 'scheme = "rk45"'),
    GOOD.replace('[model]\nkind = "pendulum"', '[model]\nkind = "pendulum"\nlength = -2'),
    GOOD.replace("[method]", "[initial]\nq = [1.2, 0.0]\n[method]"),
    GOOD.replace("[method]", "[initial]\nq = [1.0]\n[method]"),
    GOOD.replace("[method]", "[initial]\nq = [0.0, 0.0]\nv = [0.0, 0.0]\noff_constraint = true\n[method]"),
    GOOD.replace("t_end = 1.0", "t_end = 1.0\n[output]\nevery = 0"),
    GOOD.replace("t_end = 1.0", "t_end = 1.0\n[sweep]\nh = [0.01]"),
    method('preset = "fast"'),
    method('preset = "robust"\nalpha_g = 3.0'),
    method('preset = "projection"\ngeometric = "cvsgf"'),
    velocity("alpha_v = -1.0"),
    velocity("alpha_v = inf"),
    velocity('alpha_v = "fast"'),
    method('geometric = "cvsgf"\nalpha_g = "fast"'),
    method('geometric = "newton"\nalpha_g = -2.0'),
    method('energy = "projected"\nposition_weight = -1.0'),
    method('geometric = "cvsgf"\nzeta = 20.0\nalpha_v = 3.0'),
    method('preset = "projection"\ntolerance = 0.0'),
    method('preset = "projection"\ntolerance = nan'),
    method('preset = "projection"\nmax_iterations = 0'),
    method('preset = "projection"\nmax_iterations = -1'),
    method('preset = "projection"\non_failure = "ignore"'),
    method('geometric = "cvsgf"\nzeta = 20.0\ntolerance = 1e-9'),
    # Diverges part-way: a simulation error, not a scenario error.
    """
[model]
kind = "pendulum"
[initial]
q = [1.001, 0.0]
off_constraint = true
[method]
geometric = "cvsgf"
alpha_g = 2e6
[integrator]
scheme = "euler"
h = 0.01
t_end = 20.0
""",
]


def python_error(run):
    with pytest.raises(cdyn.Error) as info:
        run()
    return info.value


@pytest.mark.parametrize("text", BAD, ids=range(len(BAD)))
def test_bad_input_raises_the_cli_message(cli, tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = cli("run", path, "--out", tmp_path / "out")
    assert out.returncode != 0 and out.stderr.count("\n") == 1 and out.stderr.startswith("error: "), out.stderr
    line = out.stderr.rstrip("\n")[len("error: ") :]
    e = python_error(lambda: cdyn.run(cdyn.load(path)))
    message = str(e)
    if isinstance(e, cdyn.SimulationError):
        # The CLI adds where it wrote the output; Python keeps the rows in e.result.
        assert line == f"{message} (output up to that point is in {tmp_path / 'out'})"
        assert e.result.error == message and e.result.table.shape[0] >= 1
        partial = cdyn.run(cdyn.load(path), check=False)
        assert partial.error == message
    else:
        assert isinstance(e, cdyn.ScenarioError)
        assert message == line
    # The same text given as a string: the same message, naming what the string is called.
    e2 = python_error(lambda: cdyn.run(cdyn.loads(text, file=str(path))))
    assert type(e2) is type(e) and str(e2) == message


def test_missing_file(cli, tmp_path):
    path = tmp_path / "nope.toml"
    out = cli("run", path, "--out", tmp_path)
    e = python_error(lambda: cdyn.load(path))
    assert isinstance(e, cdyn.ScenarioError) and out.stderr.rstrip("\n") == f"error: {e}"


class NotTomlable:
    pass


@pytest.mark.parametrize(
    "data, words",
    [
        ({"model": {"kind": "pendulum"}, "integrator": {"scheme": "rk4", "h": 0.01, "t_end": NotTomlable()}}, ["integrator.t_end", "NotTomlable"]),
        ({"model": {"kind": "pendulum"}, "integrator": None}, ["integrator", "NoneType"]),
        ({"model": {"kind": "pendulum"}, 3: {}}, ["int"]),
        ({"model": {"kind": "pendulum"}, "integrator": {"scheme": "rk4", "h": 0.01, "t_end": 10**30}}, ["t_end"]),
        ({"model": {"kind": "pendulum"}}, ["<dict>", "integrator"]),
        ({"model": {"kind": "pendulum"}, "integrator": {"scheme": "rk4", "h": 0.01, "t_end": 1.0}, "extra": 1}, ["<dict>", "extra"]),
    ],
)
def test_bad_dicts_raise_scenario_errors(data, words):
    e = python_error(lambda: cdyn.from_dict(data))
    assert isinstance(e, cdyn.ScenarioError) and "\n" not in str(e)
    for w in words:
        assert w in str(e), (w, str(e))


def test_other_bad_calls_raise_python_errors():
    s = cdyn.model("pendulum", h=0.01, t_end=0.1)
    with pytest.raises(cdyn.Error, match="threads = 0"):
        cdyn.sweep(s, threads=0)
    with pytest.raises(cdyn.ScenarioError, match=r"\[sweep\]"):
        cdyn.sweep(s)
    with pytest.raises(TypeError):
        cdyn.run(42)
    with pytest.raises(cdyn.ScenarioError, match="kind"):
        cdyn.model("pendulumm")
    assert issubclass(cdyn.ScenarioError, cdyn.Error) and issubclass(cdyn.SimulationError, cdyn.Error)


def test_a_run_too_large_for_memory_is_refused_before_it_starts():
    # 1e9 steps of the pendulum: about 100 GB of samples at every = 1.
    huge = cdyn.model("pendulum", scheme="rk4", h=1e-8, t_end=10.0)
    with pytest.raises(cdyn.ScenarioError, match=r"GB of samples in memory .* every = 1\b.*every = 100 or larger, or pass force=True"):
        cdyn.run(huge)
    with pytest.raises(cdyn.ScenarioError, match="force=True"):
        cdyn.compare(huge)
