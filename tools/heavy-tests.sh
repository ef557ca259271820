#!/usr/bin/env bash
# The heavy diagnosis tests: the integration tests marked `#[ignore = "heavy: …"]`. Each
# diagnoses trials of the full Mugatu (12 uncertain parameters, often calibration on, often
# the plain selection beside the default to show a rule is needed), walking thousands of
# gaits; together they took most of CI's 75 minutes of integration tests (2026-12-02), so
# `cargo test` skips them and this script runs them, by their full names (libtest cannot
# select by the reason). Extra arguments go to the test binary (e.g. --test-threads=1).
# Run it before changing a rule of the gap diagnosis.
set -euo pipefail
cd "$(dirname "$0")/.."
names=()
for f in tests/it/*.rs; do
  module="$(basename "$f" .rs)"
  while IFS= read -r name; do
    names+=("$module::$name")
  done < <(awk '/^#\[ignore = "heavy/ { heavy = 1; next }
                heavy && match($0, /^fn [a-z_0-9]+/) { print substr($0, 4, RLENGTH - 3); heavy = 0 }' "$f")
done
if [ "${#names[@]}" -eq 0 ]; then
  echo "no heavy tests found" >&2
  exit 1
fi
echo "running ${#names[@]} heavy tests" >&2
cargo test --test it -- --ignored --exact "${names[@]}" "$@"
