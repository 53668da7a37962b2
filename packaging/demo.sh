#!/usr/bin/env bash
# `make demo`: the main job on built-in input. Until video conversion lands this prints the
# hmz-t1 design report and writes the trade-space plot.
set -euo pipefail
nelf=${1:-build/nelf}
mkdir -p demo
"$nelf" design --profile hmz-t1
"$nelf" design --profile hmz-t1 --plot demo/design-hmz-t1.png
echo "demo: wrote demo/design-hmz-t1.png (resolution over lens focal length and pitch for the hmz-t1 display)"
