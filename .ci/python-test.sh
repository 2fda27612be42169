#!/usr/bin/env bash
# The Python package against the CLI: a virtual environment under the
# target directory with maturin, NumPy and pytest from the package registry
# (pinned in python/requirements-test.txt), the `cdyn` wheel built by
# maturin (abi3, dev profile, which shares what its feature set allows of
# the workspace tests' build: about 2 minutes from cold) and installed into
# it, then pytest on python/tests with the
# `cdyn` binary to compare against. Called by .ci/run after the Rust tests.
set -euo pipefail
cd "$(dirname "$0")/.."

target="${CARGO_TARGET_DIR:-$PWD/target}"
venv="$target/py-venv"
python="${PYTHON:-python3}"
command -v "$python" >/dev/null || { echo "python-test: FAILED: no $python (need CPython >= 3.9 with venv)" >&2; exit 1; }

start=$SECONDS
if [ ! -x "$venv/bin/python" ]; then
  "$python" -m venv "$venv"
fi
# Quiet unless something fails; a cached install costs a second.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt

cdyn="$(.ci/cdyn-binary.sh)"
wheels="$target/py-wheels"
rm -rf "$wheels"
VIRTUAL_ENV="$venv" "$venv/bin/maturin" build --locked --quiet --profile dev --interpreter "$venv/bin/python" --out "$wheels"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "$wheels"/cdyn-*.whl
echo "python-test: environment and wheel ready in $((SECONDS - start)) s"

# From the tests' directory, so `import cdyn` finds the installed wheel, not python/cdyn.
cd python/tests
CDYN_BIN="$cdyn" "$venv/bin/python" -m pytest -q -p no:cacheprovider .
echo "python-test: done in $((SECONDS - start)) s"
