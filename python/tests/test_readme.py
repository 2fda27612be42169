"""The Python examples of the README and the book run as written (from the repository root)."""

import contextlib
import io
import os
import re

import pytest

from conftest import ROOT


@pytest.mark.parametrize("page", ["README.md", "docs/python.md"])
def test_the_python_examples_run_and_print_what_they_say(page):
    text = (ROOT / page).read_text()
    section = text[text.index("From Python") :]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    out = io.StringIO()
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, page, "exec"), {})
    finally:
        os.chdir(here)
    printed = out.getvalue().splitlines()
    assert printed[0].startswith("9.525") and printed[-1] == "<dict>: [integrator] invalid h = 0: must be finite and positive"


def test_the_paper_figures_example_draws_figs_3_to_5(tmp_path):
    import subprocess
    import sys

    # matplotlib is installed by .ci/python-test.sh: the example runs in CI, never skipped.
    out = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "paper_figures.py"), str(tmp_path)], capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    for stem in ("fig3_phi", "fig4_psi", "fig5_err_x"):
        assert (tmp_path / f"{stem}.png").stat().st_size > 10_000
    assert "cvsgf_energy" in out.stdout
