"""Type stubs of the native module ``cdyn._cdyn`` (use the ``cdyn`` package's functions)."""

import os
from typing import Any, Dict, List, Mapping, Optional, Tuple, Union

__version__: str

class Error(Exception):
    """Any error of cdyn; the message is the CLI's one line."""

class ScenarioError(Error):
    """A scenario that cannot be read or run as written."""

class SimulationError(Error):
    """A run that failed part-way (diverged, singular, ...)."""

class Scenario:
    """A checked scenario, as read from a file, a TOML string or a dict."""

    @property
    def file(self) -> str:
        """What errors name this scenario by: its path, ``<string>`` or ``<dict>``."""
    @property
    def has_sweep(self) -> bool:
        """Whether the scenario has a ``[sweep]`` table."""
    def to_toml(self) -> str:
        """The scenario as TOML text."""

def load(path: Union[str, os.PathLike[str]]) -> Scenario: ...
def loads(text: str, file: str = "<string>") -> Scenario: ...
def from_dict(data: Mapping[str, Any], file: str = "<dict>") -> Scenario: ...
def run(scenario: Scenario, multipliers: bool = False, force: bool = False) -> Dict[str, Any]: ...
def compare(scenario: Scenario, multipliers: bool = False, force: bool = False) -> List[Dict[str, Any]]: ...
def paper_cases(multipliers: bool = False) -> List[Dict[str, Any]]: ...
def run_sweep(scenario: Scenario, threads: Optional[int] = None) -> str: ...
def run_suite(scenarios: List[str], light: bool = False) -> Tuple[str, str]: ...
def run_precision(
    scenario: str,
    schemes: List[str] = ...,
    methods: List[str] = ...,
    h: List[float] = ...,
    t_end: Optional[float] = None,
    light: bool = False,
) -> Tuple[str, str, str]: ...
def urdf_joints(
    path: str,
    gravity: List[float],
    q: List[List[float]],
    v: List[List[float]],
) -> Tuple[List[str], List[float], List[float], List[str], List[List[Tuple[float, float, float]]], float]: ...
