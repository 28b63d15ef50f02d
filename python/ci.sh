#!/usr/bin/env bash
# The Python module's CI: a fresh venv, `pip install ./python` (maturin builds
# the extension in release), then the pytest suite against the `afford`
# command that `cargo test --workspace --release` built (target/release).
# Run from anywhere, after the workspace's tests:  bash python/ci.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(dirname "$here")"
cd "$repo"
venv="${AFFORD_VENV:-$(mktemp -d)/venv}"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip
# The extension shares the workspace's build folder: the library crates
# compiled by `cargo test --release` are reused, not built again.
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$repo/target}" \
    "$venv/bin/python" -m pip install --quiet "./python[test]"
[ -x target/release/afford ] || cargo build --release --bin afford
AFFORD_BIN="$repo/target/release/afford" "$venv/bin/python" -m pytest -q python/tests
