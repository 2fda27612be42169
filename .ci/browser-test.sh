#!/usr/bin/env bash
# The viewer in a real browser: writes report.html for a planar mechanism
# (examples/four_bar.toml) with `cdyn run --html`, loads it in headless
# Chromium at two slider positions and checks (tests/browser/check_viewer.py):
# no console message, no network request, the mechanism moved, every body
# drawn at t = 0; a compare's page and a page without a drawing load without
# error or request too; a spatial run's page (examples/arm_tethered.toml, in
# 3-D) gets the same checks, and orbiting it changes the view and playing it
# advances the frame. Installs Debian's chromium when missing; skips (exit 0,
# one line) where that cannot work: not root, no apt-get or no package registry.
# `.ci/browser-test.sh --screenshot docs/viewer.png` also remakes the picture of the README,
# `--screenshot-3d docs/viewer3d.png` the book's picture of a spatial run.
set -euo pipefail
cd "$(dirname "$0")/.."

skip() { echo "browser-test: skipped: $*"; exit 0; }

if ! command -v chromium >/dev/null; then
  [ "$(id -u)" = 0 ] || skip "chromium is missing and installing it needs root"
  command -v apt-get >/dev/null || skip "chromium is missing and there is no apt-get"
  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium; } \
    >/tmp/browser-test-apt.log 2>&1 || skip "cannot install chromium (no package registry?): $(tail -1 /tmp/browser-test-apt.log)"
fi
command -v python3 >/dev/null || skip "no python3"

start=$SECONDS
cdyn="$(.ci/cdyn-binary.sh)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$cdyn" run examples/four_bar.toml --out "$work/run" --html >/dev/null
# Also a compare's page (nine cases, one picked) and one without a drawing.
"$cdyn" compare examples/slider_crank.toml --out "$work/compare" --html >/dev/null
"$cdyn" run examples/double_pendulum.toml --out "$work/plots" --html >/dev/null
# A spatial run: the URDF arm on its tether, in 3-D.
"$cdyn" run examples/arm_tethered.toml --out "$work/spatial" --html >/dev/null
python3 tests/browser/check_viewer.py "$work/run/report.html" \
  --also "$work/compare/report.html#pos=0.4&case=2" --also "$work/plots/report.html" \
  --spatial "$work/spatial/report.html" "$@"
echo "browser-test: passed in $((SECONDS - start)) s"
