#!/usr/bin/env bash
# The layering check must fail on an include against the rule: a scratch tree with one correct
# include (inputs → core) passes, and adding one sibling include (inputs → compositor) and one upward
# include (core → player) must be reported, each with its file and line.
set -euo pipefail
source_dir=${1:?usage: reports_a_violation.sh SOURCE_DIR}
check="$source_dir/tests/layering/check_layering.sh"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/core" "$scratch/inputs" "$scratch/compositor"
printf '#pragma once\n' >"$scratch/core/image.hpp"
printf '#pragma once\n' >"$scratch/compositor/compositor.hpp"
printf '#include "core/image.hpp"\n#include <vector>\n' >"$scratch/inputs/source.cpp"
bash "$check" "$scratch" >/dev/null || { echo "a tree keeping the rule was refused"; exit 1; }

printf '#include "core/image.hpp"\n#include "compositor/compositor.hpp"\n' >"$scratch/inputs/source.cpp"
printf '#include "player/player.hpp"\n' >>"$scratch/core/image.hpp"
if out=$(bash "$check" "$scratch"); then
  echo "includes against the rule were not reported"
  exit 1
fi
grep -q '^inputs/source.cpp:2: inputs (level 2) includes compositor/compositor.hpp' <<<"$out" ||
  { echo "the sibling include was not reported: $out"; exit 1; }
grep -q '^core/image.hpp:2: core (level 0) includes player/player.hpp' <<<"$out" ||
  { echo "the upward include was not reported: $out"; exit 1; }
echo "layering check reports violations: ok"
