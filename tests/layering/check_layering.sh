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

# One grep over the tree and one awk over its lines: a process per include took 17 s.
files=()
while IFS= read -r -d '' file; do files+=("$file"); done < <(
  find core optics inputs compositor hmz_output analysis player app packaging \
    -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -print0 2>/dev/null)
if [ "${#files[@]}" -eq 0 ]; then
  echo "check_layering: no source files found under $(pwd)" >&2
  exit 2
fi
# grep -H: FILE:LINE:TEXT even for a single file.
{ grep -HnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "${files[@]}" || true; } |
  awk -v checked="${#files[@]}" '
    BEGIN {
      split("core:0 optics:1 inputs:2 compositor:2 hmz_output:2 analysis:3 player:3 app:4 packaging:5", pairs, " ")
      for (i in pairs) { split(pairs[i], kv, ":"); level[kv[1]] = kv[2] }
      bad = 0
    }
    {
      file = $0; sub(/:.*/, "", file)
      rest = substr($0, length(file) + 2); line = rest; sub(/:.*/, "", line)
      target = rest; sub(/^[^"]*"/, "", target); sub(/".*/, "", target)
      from = file; sub(/\/.*/, "", from)
      to = target; sub(/\/.*/, "", to)
      if (to == target) next                  # a file beside this one, or a generated header
      if (!(to in level)) next                # not a source folder (e.g. a third-party path)
      if (to != from && level[to] >= level[from]) {
        printf "%s:%s: %s (level %d) includes %s (%s, level %d)\n", file, line, from, level[from], target, to, level[to]
        bad = 1
      }
    }
    END {
      if (!bad) printf "layering: %d files, no include against the rule\n", checked
      exit bad
    }'
