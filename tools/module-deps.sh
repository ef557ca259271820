#!/usr/bin/env bash
# Module dependencies of the library, from its `use crate::…` paths (and the CLI's
# `robot_survey::…` paths): one line per top-level module, "module -> modules it names",
# then every arrow that does not point down the layers of docs/architecture.md.
#   tools/module-deps.sh              top-level modules, and the arrows that run up
#   tools/module-deps.sh --files DIR  the files of one folder (e.g. src/sim): which sibling
#                                     files each names, and whether they form a cycle
# Run from the repository root. Exit code 1 when an arrow runs up or sideways, or a
# folder's files form a cycle.
set -euo pipefail

if [ "${1:-}" = "--files" ]; then
  dir="${2:?usage: tools/module-deps.sh --files src/FOLDER}"
  folder="$(basename "$dir")"
  pairs=""
  for f in "$dir"/*.rs; do
    name="$(basename "$f" .rs)"
    [ "$name" = mod ] && continue
    # Siblings named as super::x or crate::folder::x (test modules included: they compile
    # with the file).
    deps=$(grep -hoE "(super|crate::${folder})::[a-z_0-9]+" "$f" 2>/dev/null \
      | sed -E 's/^.*:://' | sort -u | while read -r d; do
          [ -f "$dir/$d.rs" ] && [ "$d" != "$name" ] && echo "$d"; done | tr '\n' ' ' || true)
    echo "$name -> ${deps}"
    for d in $deps; do pairs+="$name $d"$'\n'; done
  done
  if [ -n "$pairs" ] && ! printf '%s' "$pairs" | tsort >/dev/null 2>&1; then
    echo "cycle among the files of $dir"
    exit 1
  fi
  echo "no cycle among the files of $dir"
  exit 0
fi

# Layers, top (0) to bottom; an arrow must go to a strictly lower layer.
declare -A layer=(
  [cli]=0 [report]=1 [gap]=2 [study]=2 [crosscheck]=2 [analysis]=3 [motors]=4 [dataset]=5 [interop]=5
  [sim]=6 [regression]=6 [checkpoint]=6 [io]=6 [progress]=6
)
cd src
bad=0
lines=""
for entry in *; do
  name="${entry%.rs}"
  [ "$name" = lib ] || [ "$name" = main ] && continue
  deps=$(grep -rhoE "(crate|robot_survey)::[a-z_]+" "$entry" 2>/dev/null \
    | sed -E 's/^(crate|robot_survey):://' | sort -u | grep -vx "$name" | tr '\n' ' ' || true)
  echo "$name -> ${deps}"
  for d in $deps; do
    if [ -z "${layer[$name]:-}" ] || [ -z "${layer[$d]:-}" ]; then
      lines+="  $name -> $d: module not in the layer table of this script"$'\n'
      bad=$((bad + 1))
    elif [ "${layer[$d]}" -le "${layer[$name]}" ]; then
      lines+="  $name -> $d: runs up or sideways"$'\n'
      bad=$((bad + 1))
    fi
  done
done
if [ "$bad" -gt 0 ]; then
  printf '%s arrow(s) not pointing down:\n%s' "$bad" "$lines"
  exit 1
fi
echo "0 arrows not pointing down"
