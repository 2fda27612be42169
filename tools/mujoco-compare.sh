#!/usr/bin/env bash
# The spatial chain in MuJoCo against cdyn, timed in one run
# (tools/mujoco_chain.py). Installs MuJoCo from PyPI in target/mujoco-venv.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked -p cdyn --example spatial_chain_step
venv=target/mujoco-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet "mujoco==4.0.0" "numpy>=1.24"
"$venv/bin/python" tools/mujoco_chain.py target/release/examples/spatial_chain_step
