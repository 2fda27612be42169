"""The README's "From Python" example runs as written (from the repository root)."""

import contextlib
import io
import os
import re

from conftest import ROOT


def test_the_readme_example_runs_and_prints_what_it_says():
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## From Python") :]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    out = io.StringIO()
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, "README.md", "exec"), {})
    finally:
        os.chdir(here)
    printed = out.getvalue().splitlines()
    assert printed[0].startswith("9.525") and printed[-1] == "<dict>: [integrator] invalid h = 0: must be finite and positive"
