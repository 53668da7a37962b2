#!/usr/bin/env bash
# The layering rule of the source tree (docs/ARCHITECTURE.md): a folder includes only itself and the
# folders below it; folders on one level never include each other.
#   level 0 core/         vocabulary and infrastructure
#   level 1 optics/       profile, optics, mapping, design figures: pure math
#   level 2 inputs/ compositor/ hmz_output/   the three stages, siblings
#   level 3 analysis/ player/                 offline engines; the only orchestrator
#   level 4 app/                              the CLI
#   level 5 packaging/                        what is generated from the CLI (man page, completions)
# Prints every include against the rule as FILE:LINE: FROM includes TO, and exits 1 if there is one.
#   tests/layering/check_layering.sh SOURCE_DIR
set -euo pipefail
cd "${1:?usage: check_layering.sh SOURCE_DIR}"

level() {
  case $1 in
    core) echo 0 ;;
    optics) echo 1 ;;
    inputs | compositor | hmz_output) echo 2 ;;
    analysis | player) echo 3 ;;
    app) echo 4 ;;
    packaging) echo 5 ;;
    *) echo "" ;;
  esac
}

bad=0 checked=0
while IFS= read -r -d '' file; do
  from=${file%%/*}
  from_level=$(level "$from")
  [ -z "$from_level" ] && continue
  checked=$((checked + 1))
  while IFS=: read -r line text; do
    target=$(sed -E 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]*)".*/\1/' <<<"$text")
    to=${target%%/*}
    [ "$to" = "$target" ] && continue  # a file beside this one, or a generated header
    to_level=$(level "$to")
    [ -z "$to_level" ] && continue      # not a source folder (e.g. a third-party path)
    if [ "$to" != "$from" ] && [ "$to_level" -ge "$from_level" ]; then
      echo "$file:$line: $from (level $from_level) includes $target ($to, level $to_level)"
      bad=1
    fi
  done < <(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file" || true)
done < <(find core optics inputs compositor hmz_output analysis player app packaging \
           -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -print0 2>/dev/null)

if [ "$checked" -eq 0 ]; then
  echo "check_layering: no source files found under $(pwd)" >&2
  exit 2
fi
[ "$bad" -eq 0 ] && echo "layering: $checked files, no include against the rule"
exit "$bad"
