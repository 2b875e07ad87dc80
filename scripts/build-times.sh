#!/usr/bin/env bash
# Cold build times of the crate, as a user and a contributor meet them (docs/performance.md
# keeps the figures). Each measure builds from nothing in a target directory of its own,
# with the registry already downloaded (run `cargo fetch` first on a fresh machine), and
# prints the wall time in seconds; `cargo build --timings` reports are left in the
# measure's directory under WORK.
#
#   bash scripts/build-times.sh                 # all measures
#   bash scripts/build-times.sh dependent       # one of: dependent all-features test paper
#
# dependent     a new crate whose only dependency is `nonsmooth` (default features),
#               `cargo build --release` (budget: 75 s on two cores)
# all-features  `cargo build --release --all-features` of this crate (budget: 3 min)
# test          `cargo test --no-run`, the build of the README's test command (budget:
#               5 min with the tests' run)
# paper         `cargo build --release --features plot --example paper`
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
WORK=${WORK:-$(mktemp -d /tmp/nonsmooth-build.XXXXXX)}
mkdir -p "$WORK"
JOBS=${JOBS:-$(nproc)}
export CARGO_INCREMENTAL=0

# Runs a command, prints its wall time in seconds (its output goes to $WORK/last.log).
seconds() {
  local start end
  start=$(date +%s.%N)
  "$@" >"$WORK/last.log" 2>&1 || { tail -20 "$WORK/last.log" >&2; return 1; }
  end=$(date +%s.%N)
  python3 -c "print(f'{$end - $start:.1f}')"
}

dependent() {
  local dir="$WORK/dependent"
  rm -rf "$dir"
  mkdir -p "$dir/src"
  printf '%s\n' \
    '[package]' \
    'name = "uses-nonsmooth"' \
    'version = "0.1.0"' \
    'edition = "2024"' \
    '' \
    '[dependencies]' \
    "nonsmooth = { path = \"$ROOT\" }" \
    'nalgebra = "0.35"' >"$dir/Cargo.toml"
  # The prelude's example: a system built from the parts, run with events and a sampler.
  cp "$ROOT/scripts/build-times-main.rs" "$dir/src/main.rs"
  cp "$ROOT/Cargo.lock" "$dir/Cargo.lock"
  local s
  s=$(cd "$dir" && CARGO_TARGET_DIR="$dir/target" seconds cargo build --release --timings -j "$JOBS")
  echo "dependent (release, default features): $s s"
}

all_features() {
  local s
  s=$(CARGO_TARGET_DIR="$WORK/all" seconds cargo build --release --all-features --timings -j "$JOBS")
  echo "all-features (release): $s s"
}

test_build() {
  local s
  s=$(CARGO_TARGET_DIR="$WORK/test" seconds cargo test --no-run --timings -j "$JOBS")
  echo "cargo test --no-run: $s s"
}

paper() {
  local s
  s=$(CARGO_TARGET_DIR="$WORK/paper" seconds cargo build --release --features plot --example paper -j "$JOBS")
  echo "paper example (release): $s s"
}

case "${1:-all}" in
  dependent) dependent ;;
  all-features) all_features ;;
  test) test_build ;;
  paper) paper ;;
  all) dependent; all_features; test_build; paper ;;
  *) echo "unknown measure: $1" >&2; exit 2 ;;
esac
echo "(work directory: $WORK)"
