"""The paper's Figs. 3-5 (Example 1: the unit pendulum in Cartesian
coordinates, AB-3, h = 0.01, t in [0, 20]) from Python, with Matplotlib.

    pip install matplotlib            # besides the cdyn package (see docs/python.md)
    python examples/paper_figures.py out/py-figures

Runs every case of `cdyn paper` through `cdyn.example1()` and draws, for
each, |Phi| (Fig. 3), |Psi| (Fig. 4) and the error in X against the exact
solution (Fig. 5) on log scales, as `cdyn paper` does; prints the summary
table. Run it cell by cell (the `# %%` markers) in an editor that knows them.
"""

# %% Run Example 1: case name -> cdyn.Result (NumPy arrays, summary dict).
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")  # files only; remove to show windows
import matplotlib.pyplot as plt
import numpy as np

import cdyn

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/py-figures")
out.mkdir(parents=True, exist_ok=True)
results = cdyn.example1()

print(f"{'case':<24} {'max|phi|':>10} {'max|psi|':>10} {'max|err_x|':>10}")
for name, r in results.items():
    s = r.summary
    print(f"{name:<24} {s['max_abs_phi']:>10.3e} {s['max_abs_psi']:>10.3e} {s['max_abs_err_x']:>10.3e}")

# %% Figs. 3-5: one curve per case that has the quantity (the theta cases
# have no Phi: their coordinates satisfy the constraint exactly).
FIGURES = [
    ("fig3_phi", "phi", "|Φ| (geometric constraint violation)"),
    ("fig4_psi", "psi", "|Ψ| (energy constraint violation)"),
    ("fig5_err_x", "err", "|error in X| against the exact solution"),
]
for stem, quantity, label in FIGURES:
    fig, ax = plt.subplots(figsize=(9, 5.5))
    for name, r in results.items():
        y = getattr(r, quantity)
        if y is None or not np.any(y != 0.0):
            continue
        # A log scale has no zero (the start, where the error is exactly 0): leave those points out.
        ax.semilogy(r.t, np.where(y != 0.0, np.abs(y), np.nan), label=name, linewidth=1)
    ax.set(xlabel="t", ylabel=label, title=f"Example 1 [AB-3, h = 0.01]: {label}")
    ax.grid(True, which="major", alpha=0.4)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(out / f"{stem}.png", dpi=120)
    plt.close(fig)
    print(f"wrote {out / stem}.png")
