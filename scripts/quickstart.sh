#!/usr/bin/env bash
# Quick start, first command: installs the dependencies, builds uphill, and runs the main job on
# the sample data in data/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
uphill=build/release/tools/uphill/uphill
echo
echo "== uphill convert --batch data/convert_batch.csv --mu 0.005"
"$uphill" convert --batch data/convert_batch.csv --mu 0.005
