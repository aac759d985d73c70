#!/usr/bin/env bash
# Quick start, first command: installs the dependencies, builds uphill, and runs the main job on
# the sample data in data/: the fit report of both sample experiments (and a converter batch).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
uphill=build/release/tools/uphill/uphill
echo
echo "== uphill convert --batch data/convert_batch.csv --mu 0.01"
"$uphill" convert --batch data/convert_batch.csv --mu 0.01
for series in series1-fixed-D series2-fixed-L; do
  echo
  echo "== uphill report data/$series -o out/$series"
  "$uphill" report "data/$series" -o "out/$series"
done
echo
echo "== uphill fit data/series2-fixed-L (the same analysis as a table)"
"$uphill" fit data/series2-fixed-L
echo
echo "Reports: out/series1-fixed-D/report.html and out/series2-fixed-L/report.html (open in a browser)"
