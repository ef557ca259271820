#!/usr/bin/env bash
# Regenerate the reports that are quick to make (about 2 min with a release build) into a
# temporary folder and compare them byte for byte with the committed ones in reports/.
# A refactor must leave every line "same". Reports with a hand-written part (gap-published.md,
# drake-crosscheck.md) are compared on their generated part only. Long sweeps (table3, feet)
# are re-reported from their committed points files; the gap benchmark is re-scored from its
# points file. Usage: tools/check-reports.sh [path/to/survey]
set -uo pipefail
cd "$(dirname "$0")/.."
S="${1:-target/release/survey}"
[ -x "$S" ] || { echo "no binary at $S: cargo build --release first" >&2; exit 2; }
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
fails=0
same() { # generated file, committed report
  if cmp -s "$1" "reports/$2"; then echo "same  $2"; else echo "DIFF  $2"; fails=$((fails + 1)); fi
}
prefix() { # generated file, committed report whose first lines it must be
  local n; n=$(wc -l <"$1")
  if [ "$n" -gt 0 ] && head -n "$n" "reports/$2" | cmp -s - "$1"; then echo "same  $2 (generated part)"
  else echo "DIFF  $2 (generated part)"; fails=$((fails + 1)); fi
}
contained() { # generated file, committed report that must hold it verbatim
  if python3 - "$1" "reports/$2" <<'PY'
import sys
sys.exit(0 if open(sys.argv[1]).read() in open(sys.argv[2]).read() else 1)
PY
  then echo "same  $2 (generated section)"; else echo "DIFF  $2 (generated section)"; fails=$((fails + 1)); fi
}

"$S" fit --out "$T/fit" >/dev/null 2>&1
for f in survey.html survey.png survey.svg table2.csv table2.json table2.md table2.tex; do same "$T/fit/$f" "$f"; done
"$S" fit --y speed --out "$T/speed" >/dev/null 2>&1
for f in speed.md speed.json speed-froude.svg speed-froude.png; do same "$T/speed/$f" "$f"; done
"$S" fit --release 1.0.0 --format md >"$T/t2r.md" 2>/dev/null; same "$T/t2r.md" table2-release-1.0.0.md
"$S" fit --explain full-biped --release 1.0.0 >"$T/ex.txt" 2>/dev/null; same "$T/ex.txt" explain-full-biped-1.0.0.txt
"$S" laws --release 1.1.0 >"$T/t1.md" 2>/dev/null; same "$T/t1.md" table1.md
"$S" predict --leg-length 1.0 >"$T/p.txt" 2>/dev/null; same "$T/p.txt" predict-1m.txt
"$S" predict --leg-length 1.0 --from design:mugatu >"$T/pm.txt" 2>/dev/null; same "$T/pm.txt" predict-1m-mugatu.txt
for d in mugatu zippy zippy-spherical; do
  "$S" sim walk --design "$d" --plot "$T/walk-$d.svg" >"$T/walk-$d.txt" 2>/dev/null
  same "$T/walk-$d.txt" "walk-$d.txt"; same "$T/walk-$d.svg" "walk-$d.svg"
done
for law in l2 l3; do
  "$S" torque-check --design mugatu --mass-law "$law" --plot "$T/tc-$law.svg" >"$T/tc-$law.txt" 2>/dev/null
  same "$T/tc-$law.txt" "torque-check-mugatu-$law.txt"; same "$T/tc-$law.svg" "torque-check-mugatu-$law.svg"
done
mkdir -p "$T/t3" "$T/feet"
cp reports/table3.points.csv "$T/t3/"; "$S" sim table3 --out "$T/t3" >/dev/null 2>&1
for f in table3.md table3.csv table3.json table3.tex table3-velocity.svg table3-torque.svg; do same "$T/t3/$f" "$f"; done
cp reports/feet.points.csv "$T/feet/"; "$S" sim feet --out "$T/feet" >/dev/null 2>&1
for f in feet.md feet.csv feet.json feet.svg; do same "$T/feet/$f" "$f"; done
"$S" sim crosscheck --format md >"$T/cc.md" 2>/dev/null; contained "$T/cc.md" drake-crosscheck.md
"$S" gap diagnose --trials dataset/trials/published.csv --plot "$T/gp.svg" >"$T/gp.md" 2>/dev/null
prefix "$T/gp.md" gap-published.md; same "$T/gp.svg" gap-published.svg
for t in zippy-calibration zippy-top-speed zippy-spherical-speed; do
  "$S" gap explore --trials "dataset/trials/$t.csv" --samples 512 2>/dev/null | sed 's/^#/##/' >"$T/ex-$t.md"
  contained "$T/ex-$t.md" gap-published.md
done
# The gap benchmark is re-scored from its points file (no case is run again): the same
# command as the one that made it, with --merge; its exhaustively diagnosed cases are those
# the points file's specification line names.
EXF=()
while IFS= read -r e; do EXF+=(--exhaustive "$e"); done < <(python3 -c '
import json, sys
spec = open(sys.argv[1]).readline().split(" ", 4)[4]
print("\n".join(json.loads(spec)[1].get("exhaustive", [])))' reports/gap-benchmark.points.csv)
"$S" gap benchmark --design mugatu --cases-from reports/gap-benchmark-rules/main.points.csv \
  --drake tests/golden/drake/gap --drake-reference tests/golden/drake/gap-lagged \
  --drake-reference tests/golden/drake/gap-lagged-logs --drake-seeds 3 "${EXF[@]}" \
  --compare reports/gap-benchmark-rules/main.points.csv \
  --compare reports/gap-benchmark-rules/drake-lagged.points.csv \
  --compare reports/gap-benchmark-rules/drake-lagged-logs.points.csv \
  --merge reports/gap-benchmark.points.csv --points "$T/gb.points.csv" --out "$T/gb" >/dev/null 2>&1
same "$T/gb/gap-benchmark.md" gap-benchmark.md
same "$T/gb/gap-benchmark.json" gap-benchmark.json; same "$T/gb/gap-benchmark.svg" gap-benchmark.svg
echo "$fails report(s) differ"
[ "$fails" -eq 0 ]
