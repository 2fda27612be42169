#!/usr/bin/env bash
# The cost columns of docs/robots.md: cdyn's step on real robots against
# Pinocchio's ABA and MuJoCo's step, timed in one run (tools/robot_costs.py).
# Installs Pinocchio, example-robot-data and MuJoCo from PyPI in target/robot-venv.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked -p cdyn --features urdf --example robot_step
venv=target/robot-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet "pin==4.1.0" "example-robot-data==6.0.0" "mujoco==4.0.0" "numpy==2.4.6"
"$venv/bin/python" tools/robot_costs.py target/release/examples/robot_step
