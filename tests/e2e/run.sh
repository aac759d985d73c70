#!/usr/bin/env bash
# The browser test of `uphill serve`: starts the given (already built) program on a free loopback
# port with a temporary experiment folder, runs serve.e2e.mjs in headless Chromium, stops the
# server. Builds nothing. Exit 77 (ctest: skipped) when node, npm or chromium is missing.
#   tests/e2e/run.sh PATH/TO/uphill [SCREENSHOT_DIR] [SCRIPT]
# SCRIPT: serve.e2e.mjs (default: rows typed by hand) or video.e2e.mjs (a trial's video, which
# also needs UPHILL_MAKE_VIDEO, the path of tools/make_video).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
program=${1:?usage: run.sh PATH/TO/uphill [SCREENSHOT_DIR]}
shots=${2:-}
script=${3:-serve.e2e.mjs}
chromium=${CHROMIUM:-/usr/bin/chromium}
command -v node > /dev/null || { echo "serve e2e: skipped, node not found (scripts/install-deps.sh installs it)"; exit 77; }
[[ -x $chromium ]] || { echo "serve e2e: skipped, $chromium not found (scripts/install-deps.sh installs it)"; exit 77; }
if [[ ! -f $here/node_modules/playwright-core/package.json ]]; then
  command -v npm > /dev/null || { echo "serve e2e: skipped, npm not found"; exit 77; }
  (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
fi
[[ -n $shots ]] && mkdir -p "$shots"

work=$(mktemp -d)
log=$work/serve.log
pid=
cleanup() {
  if [[ -n $pid ]]; then kill "$pid" 2> /dev/null || true; wait "$pid" 2> /dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
"$program" serve "$work/experiment" --port 0 > "$log" 2>&1 &
pid=$!
url=
for _ in $(seq 1 100); do  # at most 10 s
  url=$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$log" | head -n 1 || true)
  [[ -n $url ]] && break
  kill -0 "$pid" 2> /dev/null || break
  sleep 0.1
done
[[ -n $url ]] || { echo "serve e2e: the server did not start:"; cat "$log"; exit 1; }
UPHILL_URL=$url UPHILL_EXP_DIR=$work/experiment UPHILL_E2E_SCREENSHOTS=$shots CHROMIUM=$chromium \
  UPHILL_E2E_WORK=$work timeout 170 node "$here/$script"
