#!/usr/bin/env bash
# Prints the path of the `cdyn` binary that the workspace tests run
# (target/debug/cdyn), building it if needed. It is built with the tests'
# feature set, so after the tests this is a no-op; `cargo build -p
# cdyn-cli` would build 45 crates again with another (3.4 minutes cold).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --locked --all-targets --no-run --quiet >&2
echo "$(cargo metadata --format-version 1 --no-deps | sed 's/.*"target_directory":"\([^"]*\)".*/\1/')/debug/cdyn"
