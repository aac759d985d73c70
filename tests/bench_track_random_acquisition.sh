#!/usr/bin/env bash
# A draw of `uphill bench track --random 40 --seed 9998171038873176079` where the search along the
# path took a tape mark for the body, replayed with --draw (rendered by POV-Ray at test time, about
# 160 s of CPU, cached in the build tree after). Truth: the renderer's projected centre and
# uphill::Motion (src/motion), as the benchmark states.
#   ce3de63a  two-tone spheroid (dark green and cream) on tiles, at rest beside the black tape
#             mark at 300 mm, then rolling down. kVideoTrackerVersion 17 fitted its outline on the
#             tape mark in the first frame (it stands out by 8.8 noise levels; the body's cream
#             half matches the tiles) and stayed there: 42.7 px RMS, 40 of 40 frames silent wrong.
#             Now a place found anew must stand out by 10 noise levels (kAcquireMinStandOut).
# Known and left: its last four frames drift 1.1-1.4 px off as the dark half turns into view
# (silent wrong; docs/track.md lists the hard cases).
#   bash tests/bench_track_random_acquisition.sh UPHILL_VISION_PROGRAM CACHE_DIR
set -euo pipefail
program="$1"
cache="$2"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$program" bench track --random 40 --seed 9998171038873176079 --draw ce3de63a \
  --random-cache "$cache" --json "$out/random.json" > "$out/stdout.txt"
cat "$out/stdout.txt"
/usr/bin/python3 - "$out/random.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
(draw,) = doc["draws"]
assert draw["id"] == "ce3de63a", draw["id"]
core = draw["core"]
# Measured: 0.54 px RMS, 38 of 40 frames found, 4 silent wrong (the drift above).
assert core["px_rms"] is not None and core["px_rms"] <= 0.7, core
assert core["frames_found"] >= 36, core
assert core["silent_wrong"] <= 4, core
print("random bench acquisition: ok")
PY
