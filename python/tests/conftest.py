"""Shared fixtures: the `cdyn` CLI binary the Python results are checked against."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Runs the `cdyn` binary (path in $CDYN_BIN, set by .ci/python-test.sh)."""
    binary = os.environ.get("CDYN_BIN")
    if not binary or not os.path.exists(binary):
        pytest.fail("set CDYN_BIN to the cdyn binary (cargo build -p cdyn-cli); .ci/python-test.sh does")

    def run(*args):
        return subprocess.run([binary, *map(str, args)], capture_output=True, text=True)

    return run


def read_csv(path):
    """The CSV's header and rows, each value parsed with Python's float
    (a correctly rounded parse, as the writer's shortest repr needs)."""
    lines = pathlib.Path(path).read_text().splitlines()
    return lines[0].split(","), [[float(x) for x in line.split(",")] for line in lines[1:]]
