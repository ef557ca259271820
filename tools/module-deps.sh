#!/usr/bin/env bash
# Module dependencies of the library, from its `use crate::…` paths (and the CLI's
# `robot_survey::…` paths): one line per top-level module, "module -> modules it names".
# Run from the repository root. docs/architecture.md lists the arrows that still run up.
set -euo pipefail
cd src
for entry in *; do
  name="${entry%.rs}"
  [ "$name" = lib ] || [ "$name" = main ] && continue
  deps=$(grep -rhoE "(crate|robot_survey)::[a-z_]+" "$entry" 2>/dev/null \
    | sed -E 's/^(crate|robot_survey):://' | sort -u | grep -vx "$name" | tr '\n' ' ' || true)
  echo "$name -> ${deps}"
done
