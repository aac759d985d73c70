"""Peers of `uphill bench track`: OpenCV's CSRT and KCF trackers (centre of their box) and
HoughCircles (circle nearest the previous one), on the same clips, decoding included.

Usage: track_peers.py [--positions DIR] NAME VIDEO TRUTH_CSV R0 [NAME VIDEO TRUTH_CSV R0 ...]
  TRUTH_CSV: frame,t,x,z,u,v,visibility (synthetic_clip.hpp); R0: the ball's outline radius in
  the first frame, px. The trackers start from the true box of the first frame.
Prints a first line "versions Python X OpenCV Y", then one line per method and clip:
method clip fps rms_px frames_compared peak_bytes (peak resident memory, peak_memory.py)
With --positions DIR, each method's centre in every frame also goes to DIR/NAME.METHOD.csv
(frame,u,v; u and v empty where the method reports nothing), for the robustness table of
`uphill bench track`, which scores them itself (pixels and millimetres).
fps: frames per CPU-second of the process (time.process_time(), cv2.setNumThreads(1)), as uphill's.
RMS of (u, v) over the frames with the ball present and at least half visible, where the
method reports a position (frames it misses are not counted; their number shows in frames).
"""
import csv
import math
import sys
import time

import cv2

import peak_memory

cv2.setNumThreads(1)


def read_truth(path):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            if r["u"] == "":
                rows.append(None)
            else:
                rows.append((float(r["u"]), float(r["v"]), float(r["visibility"])))
    return rows


def make_tracker(name):
    for owner in (cv2, getattr(cv2, "legacy", None)):
        factory = getattr(owner, "Tracker%s_create" % name, None) if owner else None
        if factory:
            return factory()
    raise RuntimeError("cv2 has no %s tracker" % name)


def run_tracker(name, video, u0, v0, r0):
    cap = cv2.VideoCapture(video, cv2.CAP_FFMPEG)
    out = []
    tracker = make_tracker(name)
    start = time.process_time()
    ok, frame = cap.read()
    box = (int(round(u0 - r0)), int(round(v0 - r0)), int(round(2 * r0)), int(round(2 * r0)))
    tracker.init(frame, box)
    out.append((u0, v0))
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        found, b = tracker.update(frame)
        out.append((b[0] + b[2] / 2.0 - 0.5, b[1] + b[3] / 2.0 - 0.5) if found else None)
    return out, time.process_time() - start


def run_hough(video, u0, v0, r0):
    cap = cv2.VideoCapture(video, cv2.CAP_FFMPEG)
    out = []
    last = (u0, v0)
    start = time.process_time()
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
        grey = cv2.medianBlur(grey, 5)
        circles = cv2.HoughCircles(grey, cv2.HOUGH_GRADIENT, dp=1, minDist=r0, param1=100, param2=20,
                                   minRadius=int(0.8 * r0), maxRadius=int(math.ceil(1.25 * r0)))
        if circles is None:
            out.append(None)
            continue
        best = min(circles[0], key=lambda c: (c[0] - last[0]) ** 2 + (c[1] - last[1]) ** 2)
        last = (float(best[0]), float(best[1]))
        out.append(last)
    return out, time.process_time() - start


def score(truth, found):
    s, n = 0.0, 0
    for t, p in zip(truth, found):
        if t is None or t[2] < 0.5 or p is None:
            continue
        s += (p[0] - t[0]) ** 2 + (p[1] - t[1]) ** 2
        n += 1
    return (math.sqrt(s / n) if n else float("nan")), n


def write_positions(path, found):
    with open(path, "w") as f:
        f.write("frame,u,v\n")
        for k, p in enumerate(found):
            f.write("%d,%s,%s\n" % (k, "" if p is None else "%.4f" % p[0], "" if p is None else "%.4f" % p[1]))


def main(args):
    positions = None
    if args[:1] == ["--positions"]:
        positions, args = args[1], args[2:]
    print("versions Python %s OpenCV %s" % (sys.version.split()[0], cv2.__version__), flush=True)
    for i in range(0, len(args), 4):
        name, video, truth_csv, r0 = args[i], args[i + 1], args[i + 2], float(args[i + 3])
        truth = read_truth(truth_csv)
        u0, v0 = truth[0][0], truth[0][1]
        runs = [("CSRT", lambda: run_tracker("CSRT", video, u0, v0, r0)),
                ("KCF", lambda: run_tracker("KCF", video, u0, v0, r0)),
                ("HoughCircles", lambda: run_hough(video, u0, v0, r0))]
        for method, run in runs:
            peak_memory.reset_peak()
            found, seconds = run()
            peak = peak_memory.peak_bytes()
            rms, n = score(truth, found)
            if positions:
                write_positions("%s/%s.%s.csv" % (positions, name, method), found)
            print("%s %s %.3f %.6f %d %d" % (method, name, len(found) / seconds, rms, n, peak),
                  flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
