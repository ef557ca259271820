#!/usr/bin/env bash
# Suggested vs default trials: hip Coulomb friction at M N·m (default 0.006, where it and hip
# damping explain the six test conditions alike) with 3 % noise; three more trials either
# suggested by `survey gap suggest` or at the design's own drives (0.97, 1, 1.03×); the answer
# and the truth's posterior after each.
# Run from the repository root after `cargo build --release`: tools/gap-suggest-check.sh [seeds]
# Another truth: EFFECT=soft_ground M=1e8 tools/gap-suggest-check.sh 10
# Suggestions off the forward gait too: SUGGEST_ARGS=--any-gait tools/gap-suggest-check.sh 10
set -euo pipefail
S="$(pwd)/${SURVEY:-target/release/survey}"
E="${EFFECT:-hip_coulomb_friction}"
M="${M:-0.006}"
N="${1:-10}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cp tests/data/gap/conditions-6.csv tests/data/gap/mugatu-two-uncertain.toml "$work/"
cd "$work"
cat > default3.csv <<'CSV'
label,design,leg_length_m,frequency_hz,source
d-f0.97x,mugatu-two-uncertain.toml,0.153,1.2028,default repeat
d-f1x,mugatu-two-uncertain.toml,0.153,1.24,default repeat
d-f1.03x,mugatu-two-uncertain.toml,0.153,1.2772,default repeat
CSV
verdict() { # the answer and the truth's probability
  "$S" gap diagnose --trials "$1" --format json 2>/dev/null | python3 -c '
import json, sys
d = json.load(sys.stdin)
p = {l["explanation"]: l["probability"] for l in d["posterior"]}
print(f"{d[\"answer\"][\"kind\"]}, P(truth) = {p.get(sys.argv[1], 0.0):.3f}")' "$E"
}
for seed in $(seq 1 "$N"); do
  "$S" gap synth --conditions conditions-6.csv --effect "$E=$M" --noise 0.03 --seed "$seed" --out base.csv 2>/dev/null
  # shellcheck disable=SC2086 # SUGGEST_ARGS: extra flags, word-split on purpose
  "$S" gap suggest --trials base.csv --budget 3 ${SUGGEST_ARGS:-} --out next.csv >/dev/null 2>&1
  "$S" gap synth --conditions next.csv --effect "$E=$M" --noise 0.03 --seed $((seed + 1000)) --out nextm.csv 2>/dev/null
  "$S" gap synth --conditions default3.csv --effect "$E=$M" --noise 0.03 --seed $((seed + 1000)) --out defm.csv 2>/dev/null
  (cat base.csv; tail -n +2 nextm.csv) > withnext.csv
  (cat base.csv; tail -n +2 defm.csv) > withdef.csv
  echo "seed $seed | suggested: $(verdict withnext.csv) | default: $(verdict withdef.csv)"
done
