#!/usr/bin/env bash
# Quick start, first command: installs the dependencies, builds uphill, and runs the main job on
# the sample data in data/: the fit reports of the sample experiments (the third one's trials are
# videos, rendered first by scripts/make-sample-videos.sh), and a converter batch.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
uphill=build/release/tools/uphill/uphill
echo
echo "== uphill convert --batch data/convert_batch.csv --mu 0.01"
"$uphill" convert --batch data/convert_batch.csv --mu 0.01
echo
echo "== bash scripts/make-sample-videos.sh (the recordings of data/series3-video)"
bash scripts/make-sample-videos.sh
for series in series1-fixed-D series2-fixed-L series3-video; do
  echo
  echo "== uphill report data/$series -o out/$series"
  "$uphill" report "data/$series" -o "out/$series"
done
echo
echo "== uphill fit data/series2-fixed-L (the same analysis as a table)"
"$uphill" fit data/series2-fixed-L
echo
echo "Reports: out/series1-fixed-D/report.html, out/series2-fixed-L/report.html and"
echo "out/series3-video/report.html (Y and mu from the trials' videos) (open in a browser)"
