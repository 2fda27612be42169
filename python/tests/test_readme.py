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
