#!/usr/bin/env bash
# Compares the outputs of two afford binaries byte for byte.
#
# Usage: scripts/byte-identical.sh BASE_BINARY NEW_BINARY
#   SKIP_BENCH=1  leave out the two benchmarks (`bench safety`, `bench monitor`:
#                 about two and a half minutes per binary)
#
# For every examples/*.yaml: `afford plan FILE -o plan.json --svg plan.svg`,
# `--format csv`, and `afford check FILE plan.json --physics --json`; for every
# examples/monitor/*.yaml: `afford run FILE -o run.json --svg run.svg` and
# `--format csv`; then `afford bench safety --scenarios 100 --json` and
# `afford bench monitor --json`. Each command's exit code is an output too.
# `bench monitor` reports two wall-clock medians (median_observe_us,
# median_replan_ms), `bench safety` its planning times (median_s, p99_s,
# max_s); they are masked before hashing, every other byte counts.
#
# Prints one line per output: `same|DIFF  BASE_SHA256  NEW_SHA256  NAME`, and
# exits 1 when any output differs, 2 on bad usage.
set -euo pipefail

if [[ $# -ne 2 || ! -x $1 || ! -x $2 ]]; then
    echo "usage: $0 BASE_BINARY NEW_BINARY (both executable)" >&2
    exit 2
fi
base=$(realpath "$1")
new=$(realpath "$2")
repo=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# run BIN OUT_DIR NAME ARGS...: runs `BIN ARGS...` in the repository root with
# standard output to OUT_DIR/NAME and the exit code to OUT_DIR/NAME.rc.
run() {
    local bin=$1 out=$2 name=$3
    shift 3
    local rc=0
    (cd "$repo" && "$bin" "$@" >"$out/$name" 2>"$out/$name.stderr") || rc=$?
    echo "$rc" >"$out/$name.rc"
}

# outputs BIN OUT_DIR: every output of one binary into OUT_DIR.
outputs() {
    local bin=$1 out=$2
    mkdir -p "$out"
    local file stem
    for file in "$repo"/examples/*.yaml; do
        stem=plan-$(basename "$file" .yaml)
        run "$bin" "$out" "$stem.stdout" plan "examples/$(basename "$file")" \
            -o "$out/$stem.json" --svg "$out/$stem.svg"
        run "$bin" "$out" "$stem.csv" plan "examples/$(basename "$file")" --format csv
        run "$bin" "$out" "$stem.check.json" check "examples/$(basename "$file")" \
            "$out/$stem.json" --physics --json
    done
    for file in "$repo"/examples/monitor/*.yaml; do
        stem=run-$(basename "$file" .yaml)
        run "$bin" "$out" "$stem.stdout" run "examples/monitor/$(basename "$file")" \
            -o "$out/$stem.json" --svg "$out/$stem.svg"
        run "$bin" "$out" "$stem.csv" run "examples/monitor/$(basename "$file")" --format csv
    done
    if [[ ${SKIP_BENCH:-0} != 1 ]]; then
        run "$bin" "$out" bench-safety.json bench safety --scenarios 100 --json
        run "$bin" "$out" bench-monitor.json bench monitor --json
        sed -E -i 's/"(median_observe_us|median_replan_ms)": [-0-9.eE+]+/"\1": MASKED/' \
            "$out/bench-monitor.json"
        sed -E -i 's/"(median_s|p99_s|max_s)": [-0-9.eE+]+/"\1": MASKED/' \
            "$out/bench-safety.json"
    fi
    # Standard error carries timings and absolute paths; it is not an output.
    rm -f "$out"/*.stderr
    # `plan -o` prints nothing; `run -o` prints a summary with wall-clock
    # decision times, which are not compared either.
    rm -f "$out"/run-*.stdout
}

outputs "$base" "$work/base"
outputs "$new" "$work/new"

status=0
names=$( (cd "$work/base" && ls; cd "$work/new" && ls) | sort -u)
for name in $names; do
    a=$( [[ -f $work/base/$name ]] && sha256sum <"$work/base/$name" | cut -d' ' -f1 || echo missing)
    b=$( [[ -f $work/new/$name ]] && sha256sum <"$work/new/$name" | cut -d' ' -f1 || echo missing)
    if [[ $a == "$b" ]]; then
        verdict=same
    else
        verdict=DIFF
        status=1
    fi
    echo "$verdict  $a  $b  $name"
done
exit "$status"
