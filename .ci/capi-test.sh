#!/usr/bin/env bash
# The C API from C: the committed crates/cdyn-capi/include/cdyn.h must be
# what cbindgen (from crates.io, pinned, installed once under the target
# directory, unoptimized: about 1.5 minutes the first time) makes of
# src/api.rs now; then examples/pd_pendulum.c is compiled by gcc against it
# and the shared library, and run. Called by .ci/run after the Rust tests:
# the library is built as part of the whole workspace with all targets, the
# feature set of their build, which it shares (`-p cdyn-capi` alone unifies
# the dependencies' features differently and rebuilt cdyn and cdyn-cli:
# 5.6 minutes of a cold CI run).
set -euo pipefail
cd "$(dirname "$0")/.."

CBINDGEN_VERSION=0.29.4
target="$(cargo metadata --format-version 1 --no-deps | sed 's/.*"target_directory":"\([^"]*\)".*/\1/')"
cbindgen="$target/tools/bin/cbindgen"
start=$SECONDS
if ! "$cbindgen" --version 2>/dev/null | grep -qx "cbindgen $CBINDGEN_VERSION"; then
  cargo install cbindgen --version "$CBINDGEN_VERSION" --locked --debug --quiet --root "$target/tools"
fi
(cd crates/cdyn-capi && "$cbindgen" --quiet --config cbindgen.toml --output "$target/cdyn.h")
if ! diff -u crates/cdyn-capi/include/cdyn.h "$target/cdyn.h"; then
  echo "capi-test: FAILED: crates/cdyn-capi/include/cdyn.h is stale; regenerate it: (cd crates/cdyn-capi && $cbindgen --config cbindgen.toml --output include/cdyn.h)" >&2
  exit 1
fi
cargo build --workspace --all-targets --locked --quiet
gcc -std=c99 -Wall -Wextra -Werror examples/pd_pendulum.c -Icrates/cdyn-capi/include \
  -L"$target/debug" -lcdyn_capi -lm -o "$target/pd_pendulum"
LD_LIBRARY_PATH="$target/debug" "$target/pd_pendulum" examples/pd_pendulum.toml
echo "capi-test: done in $((SECONDS - start)) s"
