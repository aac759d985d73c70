#!/usr/bin/env bash
# Draws of `uphill bench track --random 17 --seed 14442369650050460584` where the tracker once
# failed, replayed with --draw (rendered by POV-Ray at test time, about 35 s of CPU, cached in
# the build tree after). Truth: the renderer's projected centre and uphill::Motion (src/motion),
# as the benchmark states. Each is a body at rest for the whole clip, so the background under it
# is never seen; the tracker before these fixes (kVideoTrackerVersion 16) gave:
#   61e48118  striped sphere on tiles: 4.98 px RMS, 19 frames silent wrong (the model's outline
#             held off the body by the stripes; now the edge fit measures it)
#   eddd68d6  two-tone sphere on paper: found in 0 of 30 frames (its colour matches the paper on
#             one side; now the search also proposes places by the grey step across the outline)
#   10945462  spheroid on thick painted rods: found in 0 of 40 frames (the rods inside every
#             candidate's outline outranked it; now the search walks down the candidates)
# and the rest position analyse-track takes from each (the report's Y) now states an uncertainty
# that holds the truth: within 3 u (before: u = scatter/sqrt(n) alone, pulls of 30 and more).
# And of `--random 8 --seed 8865490429367052905`:
#   fa10df48  banded sphere on paper, 960x540, at the fall-off point: it drops through the gap
#             after 20 frames. kVideoTrackerVersion 23 went on reporting it between the rods for
#             the 20 frames after (a disc there meets the rods' edges as the body did); now a fit
#             whose ends along the rods do not stand out of the table is not the body
#             (path_end_steps.hpp), and no frame after the fall is reported. Known and left: the
#             20 frames before it are found 1.5-35 px off (the body sits so deep between the rods
#             that little of its outline shows).
#   bash tests/bench_track_random_regressions.sh UPHILL_VISION_PROGRAM CACHE_DIR
set -euo pipefail
program="$1"
cache="$2"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$program" bench track --random 17 --seed 14442369650050460584 --draw 61e48118,eddd68d6,10945462 \
  --random-cache "$cache" --json "$out/random.json" > "$out/stdout.txt"
cat "$out/stdout.txt"
/usr/bin/python3 - "$out/random.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
draws = {d["id"]: d for d in doc["draws"]}
assert sorted(draws) == ["10945462", "61e48118", "eddd68d6"], sorted(draws)
# (most px RMS, least share of the frames in view found): measured 0.38, 0.052, 0.23 px; 40/40,
# 30/30, 40/40.
bounds = {"61e48118": (0.5, 1.0), "eddd68d6": (0.12, 1.0), "10945462": (0.35, 0.95)}
for name, (most_px, least_found) in bounds.items():
    core = draws[name]["core"]
    assert core["silent_wrong"] == 0, (name, core)
    assert core["frames_found"] >= least_found * core["frames_in_view"], (name, core)
    assert core["px_rms"] is not None and core["px_rms"] <= most_px, (name, core)
    analysis = draws[name]["analysis"]
    assert analysis["kind"] == "rest", (name, analysis)
    (y,) = analysis["pulls"]
    assert y["u"] > 0 and abs(y["error"]) <= 3 * y["u"], (name, y)
PY
"$program" bench track --random 8 --seed 8865490429367052905 --draw fa10df48 \
  --random-cache "$cache" --json "$out/fallen.json" > "$out/fallen.txt"
cat "$out/fallen.txt"
/usr/bin/python3 - "$cache/8865490429367052905" "$out/fallen.json" <<'PY'
import csv, glob, json, os, sys
root = sys.argv[1]
# The clip of this run's generator (a cache can also hold one drawn by an older generator).
(draw,) = json.load(open(sys.argv[2]))["draws"]
(clip,) = [os.path.dirname(c) for c in glob.glob(root + "/*/condition.json")
           if json.load(open(c))["name"] == "random-fa10df48" and json.load(open(c))["generator"] == draw["condition"]["generator"]]
gone = {int(r["frame"]) for r in csv.DictReader(open(clip + "/truth.csv")) if not r["u"]}
track = list(csv.DictReader(open(root + "/tracks/fa10df48/core.csv")))
assert len(gone) == 20, len(gone)  # the renderer's frames without the body: 20 to 39
reported = [int(r["frame"]) for r in track if int(r["frame"]) in gone and r["u"]]
assert not reported, ("a position reported after the body fell", reported)
PY
echo "random bench regressions: ok"
