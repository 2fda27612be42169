"""cdyn: constrained multibody dynamics in redundant coordinates, with
constraint and energy violations pushed back (CVSGF), from Python.

A thin layer over the Rust library and the ``cdyn`` command line: scenarios
are read, cases run and errors worded exactly as ``cdyn run``, ``cdyn
compare``, ``cdyn sweep``, ``cdyn suite``, ``cdyn precision`` and ``cdyn paper`` do.
Runs release the GIL.

>>> import cdyn
>>> s = cdyn.model("pendulum", scheme="rk4", h=0.01, t_end=1.0)
>>> r = cdyn.run(s)
>>> float(r.t[-1]), r.q.shape, r.columns
(1.0, (101, 2), ['t', 'X', 'Y', 'VX', 'VY', 'phi', 'psi', 'err_x'])
>>> bool(abs(r.phi).max() < 1e-12)
True
"""

from __future__ import annotations

import json
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union
import os

import numpy as np

from . import _cdyn
from ._cdyn import Error, Scenario, ScenarioError, SimulationError

__version__: str = _cdyn.__version__

__all__ = [
    "Error",
    "ScenarioError",
    "SimulationError",
    "Scenario",
    "Result",
    "Sweep",
    "Suite",
    "Precision",
    "Simulation",
    "load",
    "loads",
    "from_dict",
    "model",
    "scenario",
    "run",
    "compare",
    "sweep",
    "suite",
    "precision",
    "example1",
]

ScenarioLike = Union[Scenario, str, "os.PathLike[str]", Mapping[str, Any]]


class Result:
    """One run: its samples as NumPy arrays and its summary as a dict.

    The samples are the rows ``cdyn run`` writes to CSV (the same values,
    bit for bit), plus the coordinates and velocities at each sample.

    Attributes:
        name: the case's name (the CSV file's stem in the CLI).
        columns: the CSV header: ``t``, the observables, ``phi``, ``psi``,
            and ``err_<observable>`` when the model has a reference solution.
        table: every sample, one row each, in the order of ``columns``.
        t: sample times.
        observables: the observables (``table``'s columns between ``t`` and
            ``phi``), one column each; ``observable_names`` names them.
        phi: the constraint violation of largest magnitude, with its sign.
        psi: the energy constraint Ψ.
        err: the error of the first observable against the reference, or
            None without a reference.
        q, v: coordinates and velocities at each sample (samples × n).
        lam: the Lagrange multipliers λ (Eq. 7) at each sampled state
            (samples × m) when the run was asked for them, else None.
        summary: the case's entry of ``summary.json`` (a plain dict).
        error: None when the run finished; else the CLI's one-line message.
    """

    # Documented slots: editors show these on the attributes.
    __slots__ = {
        "name": "The case's name (the CSV file's stem in the CLI).",
        "columns": "The CSV header: t, the observables, phi, psi, err_<observable> with a reference.",
        "table": "Every sample, one row each, in the order of columns (the CSV's values, bit for bit).",
        "q": "Coordinates at each sample (samples × n).",
        "v": "Velocities at each sample (samples × n).",
        "lam": "Lagrange multipliers λ at each sample (samples × m), or None unless asked for.",
        "summary": "The case's summary.json entry, a plain dict.",
        "error": "None when the run finished, else the CLI's one-line message.",
    }

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.summary: Dict[str, Any] = json.loads(raw["summary"])
        self.name: str = self.summary["name"]
        self.columns: List[str] = list(raw["columns"])
        self.table: np.ndarray = raw["values"]
        self.q: np.ndarray = raw["q"]
        self.v: np.ndarray = raw["v"]
        self.lam: Optional[np.ndarray] = raw["lambda"]
        self.error: Optional[str] = raw["error"]
        for a in (self.table, self.q, self.v, self.lam):
            if a is not None:
                a.flags.writeable = False

    def column(self, name: str) -> np.ndarray:
        """The column ``name`` of ``table`` (e.g. ``"X"``, ``"phi"``)."""
        return self.table[:, self.columns.index(name)]

    @property
    def t(self) -> np.ndarray:
        """Sample times (as the CSV writes them: 0.3, not 0.30000000000000004)."""
        return self.table[:, 0]

    @property
    def observable_names(self) -> List[str]:
        """Names of the observables (e.g. ``X, Y, VX, VY``; a mechanism's coordinates)."""
        return self.columns[1 : self.columns.index("phi")]

    @property
    def observables(self) -> np.ndarray:
        """The observables at each sample (samples × observables)."""
        return self.table[:, 1 : self.columns.index("phi")]

    @property
    def phi(self) -> np.ndarray:
        """The constraint value of largest magnitude at each sample, with its sign."""
        return self.column("phi")

    @property
    def psi(self) -> np.ndarray:
        """The energy constraint Ψ at each sample."""
        return self.column("psi")

    @property
    def err(self) -> Optional[np.ndarray]:
        """The error of the first observable against the reference, or None without one."""
        last = self.columns[-1]
        return self.column(last) if last.startswith("err_") else None

    def to_pandas(self) -> "Any":
        """The samples as a pandas DataFrame: the CSV's columns, then
        ``q0..`` and ``v0..`` (needs pandas, an optional dependency)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Result.to_pandas() needs pandas: pip install pandas") from e
        data = {c: self.table[:, i] for i, c in enumerate(self.columns)}
        for k in range(self.q.shape[1]):
            data[f"q{k}"] = self.q[:, k]
        for k in range(self.v.shape[1]):
            data[f"v{k}"] = self.v[:, k]
        return pd.DataFrame(data)

    def __repr__(self) -> str:
        status = "ok" if self.error is None else "failed"
        return f"<cdyn.Result {self.name!r}: {self.table.shape[0]} samples, {status}>"


class Sweep:
    """A sweep's result: ``summary`` is ``sweep.json`` as a dict; the grid's
    values and worst violations and errors as NumPy arrays (one entry per
    grid point, last axis fastest)."""

    __slots__ = {"summary": "sweep.json as a dict: scenario, scenario_hash, axes, points."}

    def __init__(self, text: str) -> None:
        self.summary: Dict[str, Any] = json.loads(text)

    @property
    def axes(self) -> Dict[str, np.ndarray]:
        """Axis name → its values."""
        return {a["name"]: np.array(a["values"], dtype=float) for a in self.summary["axes"]}

    @property
    def values(self) -> np.ndarray:
        """The axis values of each point (points × axes)."""
        return np.array([p["values"] for p in self.summary["points"]], dtype=float).reshape(-1, len(self.summary["axes"]))

    def _field(self, key: str) -> np.ndarray:
        return np.array([np.nan if p[key] is None else p[key] for p in self.summary["points"]], dtype=float)

    @property
    def max_abs_phi(self) -> np.ndarray:
        """Largest |Φ| of each point's run."""
        return self._field("max_abs_phi")

    @property
    def max_abs_psi(self) -> np.ndarray:
        """Largest |Ψ| of each point's run."""
        return self._field("max_abs_psi")

    @property
    def max_abs_err(self) -> np.ndarray:
        """NaN where there is no reference."""
        return self._field("max_abs_err")

    @property
    def errors(self) -> List[Optional[str]]:
        """Each point's failure message, or None."""
        return [p["error"] for p in self.summary["points"]]

    def __repr__(self) -> str:
        return f"<cdyn.Sweep {len(self.summary['points'])} points over {[a['name'] for a in self.summary['axes']]}>"


class Suite:
    """The method suite's result, as ``cdyn suite`` computes it: ``summary``
    is ``suite.json`` as a dict (equal to the CLI's file), ``table`` the
    table and summary lines it prints."""

    __slots__ = {
        "summary": "suite.json as a dict: light, cases (one per model, scheme and step), summary.",
        "table": "The table and the check counts cdyn suite prints.",
    }

    def __init__(self, text: str, table: str) -> None:
        self.summary: Dict[str, Any] = json.loads(text)
        self.table: str = table

    @property
    def cases(self) -> List[Dict[str, Any]]:
        """One entry per model, scheme and step: its runs (one per method) and checks."""
        return list(self.summary["cases"])

    @property
    def misses(self) -> List[str]:
        """Every failed check, ``model scheme h=… (letter): numbers``."""
        return list(self.summary["summary"]["misses"])

    def __repr__(self) -> str:
        return f"<cdyn.Suite {len(self.summary['cases'])} groups, {len(self.misses)} misses>"


class Precision:
    """A work-precision diagram, as ``cdyn precision`` computes it:
    ``summary`` is ``precision.json`` as a dict, ``csv`` the text of
    ``precision.csv``, ``table`` the table it prints. The errors, steps and
    evaluations equal the CLI's; the wall-clock times are this run's own."""

    __slots__ = {
        "summary": "precision.json as a dict: scenario, t_end, sample_interval, reference, lines, cheapest.",
        "csv": "precision.csv as text: one row per scheme, method and step.",
        "table": "The table cdyn precision prints.",
    }

    def __init__(self, text: str, csv: str, table: str) -> None:
        self.summary: Dict[str, Any] = json.loads(text)
        self.csv: str = csv
        self.table: str = table

    @property
    def lines(self) -> List[Dict[str, Any]]:
        """One per scheme and method: its points (coarsest step first) and observed order."""
        return list(self.summary["lines"])

    @property
    def reference(self) -> Dict[str, Any]:
        """What the errors are measured against: a closed form, or a fine RK-4 and its error bound."""
        return dict(self.summary["reference"])

    @property
    def cheapest(self) -> List[Dict[str, Any]]:
        """For each target error some line reaches, the line that gets there in the least wall time."""
        return list(self.summary["cheapest"])

    def __repr__(self) -> str:
        return f"<cdyn.Precision {len(self.lines)} lines of {self.summary['scenario']}>"


class Simulation:
    """A scenario's case stepped from Python instead of run to its end:
    inputs (the scenario's ``[[inputs]]``) set and outputs (its ``[output]
    select``, by default every CSV column of ``cdyn run``) read between
    steps; the state read, written, saved and restored. Steps release the GIL.

    Each Simulation has a model of its own, so two never share inputs. A
    changed input restarts the scheme (AB-3 and ABM-4 take RK-4 steps again)
    and keeps the energy balance (see the book's page on inputs and FMUs).
    Joint limits are held as ``cdyn run`` holds them (``limits`` lists what
    they did); a snapshot saves the limits held with the state.

    >>> import cdyn
    >>> sim = cdyn.Simulation("examples/pd_pendulum.toml")  # doctest: +SKIP
    >>> sim.set_input("tau", 0.5); sim.step(10); sim.outputs()  # doctest: +SKIP
    """

    __slots__ = {"_sim": "The native simulation."}

    def __init__(self, source: ScenarioLike) -> None:
        self._sim = _cdyn.Simulation(scenario(source))

    @property
    def input_names(self) -> List[str]:
        """The inputs' names, in order (their positions for ``set_input``)."""
        return list(self._sim.input_names)

    @property
    def output_names(self) -> List[str]:
        """The outputs' names, in the order ``outputs()`` returns them."""
        return list(self._sim.output_names)

    @property
    def t(self) -> float:
        """Current time (steps × h)."""
        return float(self._sim.t)

    @property
    def steps(self) -> int:
        """Steps taken."""
        return int(self._sim.steps)

    @property
    def h(self) -> float:
        """The step size."""
        return float(self._sim.h)

    def set_input(self, input: Union[int, str], value: float) -> None:
        """Sets an input by position or name; takes effect from the next step.
        A value that is not finite, or an unknown input, raises cdyn.Error."""
        self._sim.set_input(input, float(value))

    def input(self, index: int) -> float:
        """The current value of input ``index``."""
        return float(self._sim.input(index))

    def step(self, n: int = 1) -> None:
        """Takes ``n`` steps; a failed step raises SimulationError."""
        self._sim.step(n)

    def outputs(self) -> np.ndarray:
        """The outputs at the current state, as ``output_names`` orders them
        (the values ``cdyn run`` writes to its CSV at the same step)."""
        return self._sim.outputs()

    def output(self, name: str) -> float:
        """The output ``name`` at the current state."""
        return float(self.outputs()[self.output_names.index(name)])

    def state(self) -> Tuple[np.ndarray, np.ndarray, float]:
        """The full state: positions q, velocities v and the energy input ∫Ė."""
        return self._sim.state()

    def set_state(self, q: Sequence[float], v: Sequence[float], e: float) -> None:
        """Puts the simulation at the state ``(q, v, e)`` (as ``state()``
        returns it), at the same time; the scheme starts again from there.
        With joint limits, a state past a limit raises Error, and a held
        limit the state is away from is let go."""
        self._sim.set_state(np.asarray(q, dtype=float), np.asarray(v, dtype=float), float(e))

    @property
    def limits(self) -> Optional[Dict[str, Any]]:
        """What the case's joint limits did so far, as ``summary.json``'s
        ``limits`` (``events``: each impact and release; ``velocity_exceeded``);
        None for a case without limits."""
        text = self._sim.limits_json()
        return None if text is None else json.loads(text)

    def snapshot(self) -> Any:
        """Everything needed to come back to this point of the run
        (``restore`` repeats the run from here bit for bit)."""
        return self._sim.snapshot()

    def restore(self, state: Any) -> None:
        """Goes back to a ``snapshot()`` of this simulation."""
        self._sim.restore(state)

    def __repr__(self) -> str:
        return f"<cdyn.Simulation t={self.t} inputs={self.input_names}>"


def load(path: Union[str, "os.PathLike[str]"]) -> Scenario:
    """Reads and checks the scenario file at ``path`` (as ``cdyn run`` does)."""
    return _cdyn.load(os.fspath(path))


def loads(text: str, file: str = "<string>") -> Scenario:
    """Reads and checks a scenario given as TOML text; ``file`` names it in errors."""
    return _cdyn.loads(text, file)


def from_dict(data: Mapping[str, Any], file: str = "<dict>") -> Scenario:
    """Reads and checks a scenario given as a dict of the files' schema,
    e.g. ``{"model": {"kind": "pendulum"}, "integrator": {...}}``."""
    return _cdyn.from_dict(dict(data), file)


def model(
    kind: str,
    *,
    scheme: str = "rk4",
    h: float = 0.01,
    t_end: float = 10.0,
    method: Optional[Mapping[str, Any]] = None,
    initial: Optional[Mapping[str, Any]] = None,
    every: Optional[int] = None,
    name: Optional[str] = None,
    **parameters: Any,
) -> Scenario:
    """A built-in model by name (``kind`` as in ``[model] kind``) with its
    parameters as keywords: the pendulums take theirs in ``[model]``
    (``length``, ``gravity``, ...), the other models in ``[model.parameters]``.
    ``method`` is the ``[method]`` table (default: the ``robust`` preset)."""
    m: Dict[str, Any] = {"kind": kind}
    if kind in ("pendulum", "pendulum_theta"):
        m.update(parameters)
    elif parameters:
        m["parameters"] = dict(parameters)
    data: Dict[str, Any] = {"model": m, "integrator": {"scheme": scheme, "h": h, "t_end": t_end}}
    if method is not None:
        data["method"] = dict(method)
    if initial is not None:
        data["initial"] = dict(initial)
    output = {k: v for k, v in (("every", every), ("name", name)) if v is not None}
    if output:
        data["output"] = output
    return from_dict(data)


def scenario(source: ScenarioLike) -> Scenario:
    """A Scenario from a Scenario, a dict, or a file path."""
    if isinstance(source, Scenario):
        return source
    if isinstance(source, Mapping):
        return from_dict(source)
    return load(source)


def run(source: ScenarioLike, *, check: bool = True, multipliers: bool = False, force: bool = False) -> Result:
    """Runs the scenario as ``cdyn run`` does (without writing files);
    with ``multipliers``, the result's ``lam`` holds λ at every sample.
    A run whose samples would take more than 2 GB of memory is refused
    (ScenarioError, naming the ``[output] every`` that fits) unless ``force``.

    A run that fails part-way raises SimulationError with the CLI's message
    (its ``result`` attribute holds what was recorded up to the failure);
    with ``check=False`` the Result is returned and its ``error`` says why.
    """
    result = Result(_cdyn.run(scenario(source), multipliers, force))
    if check and result.error is not None:
        e = SimulationError(result.error)
        e.result = result  # type: ignore[attr-defined]
        raise e
    return result


def compare(source: ScenarioLike, *, multipliers: bool = False, force: bool = False) -> Dict[str, Result]:
    """Runs the scenario's model under every method of ``cdyn compare``:
    method name → Result (failed methods carry their ``error``)."""
    return {r.name: r for r in map(Result, _cdyn.compare(scenario(source), multipliers, force))}


def sweep(source: ScenarioLike, *, threads: Optional[int] = None) -> Sweep:
    """Runs the scenario's ``[sweep]`` grid in parallel on ``threads`` threads
    (default: one per core), as ``cdyn sweep`` does; the result does not
    depend on ``threads``."""
    return Sweep(_cdyn.run_sweep(scenario(source), threads))


def suite(scenarios: Sequence[Union[str, "os.PathLike[str]"]] = (), *, light: bool = False) -> Suite:
    """Judges every method of ``cdyn compare`` on the shipped models (a few,
    shorter, with ``light``) and the scenario files ``scenarios``, at AB-3,
    RK-4 and ABM-4 (RATTLE and generalized-α with no control and with
    projection), h and h/2, against a fine reference, as ``cdyn suite``
    does; the result's ``summary`` equals the CLI's ``suite.json``."""
    return Suite(*_cdyn.run_suite([os.fspath(p) for p in scenarios], light))


def precision(
    path: Union[str, "os.PathLike[str]"],
    *,
    schemes: Sequence[str] = (),
    methods: Union[str, Sequence[str], None] = None,
    h: Sequence[float] = (),
    t_end: Optional[float] = None,
    light: bool = False,
) -> Precision:
    """The work-precision diagram of the scenario file at ``path``, as
    ``cdyn precision`` draws it: each scheme of ``schemes`` (by name; all by
    default) and method of ``methods`` (names of ``cdyn compare``; no
    control, robust and projection by default; ``"all"`` every one) at each
    step of ``h`` (default: the scenario's h × 4, 2, 1, 1/2, 1/4), run to
    ``t_end`` (default the scenario's), the error against the model's closed
    form or a fine RK-4, the evaluations and wall time per simulated
    second, the observed order and the cheapest line per error. ``light``
    takes three steps over a quarter of the time. Writes no files."""
    names = [methods] if isinstance(methods, str) else list(methods or [])
    return Precision(
        *_cdyn.run_precision(os.fspath(path), list(schemes), names, [float(x) for x in h], t_end, light)
    )


def example1(*, multipliers: bool = False) -> Dict[str, Result]:
    """The paper's Example 1 as ``cdyn paper`` runs it (AB-3, h = 0.01,
    t ∈ [0, 20]): case name → Result."""
    return {r.name: r for r in map(Result, _cdyn.paper_cases(multipliers))}
