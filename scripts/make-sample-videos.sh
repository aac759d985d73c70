#!/usr/bin/env bash
# Renders the recordings of the sample experiment data/series3-video (data/README.md) with
# tools/make_video, whose ground truth is exact: per setting (D = 120 … 180 mm) a trial placed just
# inside the far edge of the rest band of mu = 0.05 (1 s at rest) and one released just beyond it
# (at rest 0.5 s, then rolls up and falls off); 640 x 360 at 30 frames/s, with the lab's marks in
# view (tape on the rods at 300/600/900 mm, the crossbar's feet, a ruler). Also the camera and scene
# files of the camera that filmed them. Seeded: the same files every time. Skips the work when the
# videos are there.
#   bash scripts/make-sample-videos.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
cd "$(dirname "$0")/.."
make_video="${1:-build/release}/tools/make_video/make_video"
exp=data/series3-video
[ -f "$exp/videos/d180-roll.mp4" ] && [ -f "$exp/calibration/scene-main.json" ] && exit 0
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for D in 120 140 160 180; do
  "$make_video" "$work" --width 640 --height 360 --boards 0 --noise 1 --mu 0.05 --D "$D" \
    --x0-band -0.02 --seconds 1 --name "d$D-rest" > /dev/null
  "$make_video" "$work" --width 640 --height 360 --boards 0 --noise 1 --mu 0.05 --D "$D" \
    --x0-band 0.3 --release-time 0.5 --until-end --name "d$D-roll" > /dev/null
done
mkdir -p "$exp/videos" "$exp/calibration"
cp "$work"/d*.mp4 "$exp/videos/"
cp "$work/cam.json" "$exp/calibration/camera.json"
cp "$work/scene.json" "$exp/calibration/scene-main.json"
echo "wrote $exp/videos/ (8 clips) and $exp/calibration/"
