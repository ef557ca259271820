#!/usr/bin/env bash
# Regenerate the reports that are quick to make (about 2 min with a release build) into a
# temporary folder and compare them byte for byte with the committed ones in reports/.
# A refactor must leave every line "same". Reports with a hand-written part (gap-benchmark.md,
# gap-published.md, drake-crosscheck.md) are compared on their generated part only.
# Long sweeps (table3, feet) are re-reported from their committed points files; the gap
# benchmark is re-merged from its points file. Usage: tools/check-reports.sh [path/to/survey]
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
"$S" gap benchmark --design mugatu --quick --noise 0.03,0.05 --null-cases 300 --one-robot-nulls 300 \
  --drake tests/golden/drake/gap --merge reports/gap-benchmark.points.csv \
  --points "$T/gb.points.csv" --out "$T/gb" >/dev/null 2>&1
prefix "$T/gb/gap-benchmark.md" gap-benchmark.md
same "$T/gb/gap-benchmark.json" gap-benchmark.json; same "$T/gb/gap-benchmark.svg" gap-benchmark.svg
# The shipped default's audit (with its declared partners) on the compound and
# parameter-error cases (seventeenth session).
"$S" gap benchmark --design mugatu --quick --noise 0.03,0.05 --null-cases 300 --one-robot-nulls 300 \
  --drake tests/golden/drake/gap --audit-undeclared --merge reports/gap-benchmark-audit-partners.points.csv \
  --points "$T/gap.points.csv" --out "$T/gap" >/dev/null 2>&1
prefix "$T/gap/gap-benchmark.md" gap-benchmark-audit-partners/gap-benchmark.md
same "$T/gap/gap-benchmark.json" gap-benchmark-audit-partners/gap-benchmark.json
same "$T/gap/gap-benchmark.svg" gap-benchmark-audit-partners/gap-benchmark.svg
"$S" gap benchmark --design zippy --quick --merge reports/gap-benchmark-zippy.points.csv \
  --points "$T/gz.points.csv" --out "$T/gz" >/dev/null 2>&1
prefix "$T/gz/gap-benchmark.md" gap-benchmark-zippy/gap-benchmark.md
same "$T/gz/gap-benchmark.json" gap-benchmark-zippy/gap-benchmark.json
same "$T/gz/gap-benchmark.svg" gap-benchmark-zippy/gap-benchmark.svg
# The Drake-Lagged folders diagnosed through their no-effect trials:
# tests/golden/drake/gap-<name> gives reports/gap-benchmark-drake-<name>.
drake_reference() { # folder name, seeds (default 3)
  local r="gap-benchmark-drake-$1"
  "$S" gap benchmark --design mugatu --quick --noise 0.03,0.05 --null-cases 300 --one-robot-nulls 100 \
    --drake "tests/golden/drake/gap-$1" --drake-seeds "${2:-3}" --drake-reference \
    --merge "reports/$r.points.csv" --points "$T/$r.points.csv" --out "$T/$r" >/dev/null 2>&1
  prefix "$T/$r/gap-benchmark.md" "$r/gap-benchmark.md"
  same "$T/$r/gap-benchmark.json" "$r/gap-benchmark.json"
  same "$T/$r/gap-benchmark.svg" "$r/gap-benchmark.svg"
}
for name in lagged lagged-next lagged-heldout; do drake_reference "$name"; done
# The same with the 1x trials' robot logs: the diagnosis followed by the logged cycles.
drake_reference lagged-logs 5
# The same rules on Drake trials with logs made after them (other magnitudes; twentieth session).
drake_reference lagged-logs-heldout 5
# And on Drake trials made after the one-metric rule (twenty-second session).
drake_reference lagged-logs-heldout2 5
# Drake-SAP's trials against mugatu-ref-sap (the convex friction cone), plain and through the
# no-effect trials: with the signed velocity (eighteenth session) and compared on speed
# (criteria.walking_direction = "either"; nineteenth session, four of the nine files).
for run in convex speed; do
  for ref in "" "--drake-reference"; do
    r="gap-benchmark-drake-sap-$run${ref:+-reference}"
    "$S" gap benchmark --design mugatu --quick --noise 0.03,0.05 --null-cases 300 --one-robot-nulls 300 \
      --drake tests/golden/drake/gap --drake-design mugatu-ref-sap $ref \
      --merge "reports/$r.points.csv" --points "$T/$r.points.csv" --out "$T/$r" >/dev/null 2>&1
    prefix "$T/$r/gap-benchmark.md" "$r/gap-benchmark.md"
    same "$T/$r/gap-benchmark.json" "$r/gap-benchmark.json"
    same "$T/$r/gap-benchmark.svg" "$r/gap-benchmark.svg"
  done
done
echo "$fails report(s) differ"
[ "$fails" -eq 0 ]
