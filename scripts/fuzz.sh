#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang++, ASan + UBSan) in build/fuzz and runs each
# for the given number of seconds (default 150), one after the other.
#   bash scripts/fuzz.sh [seconds-per-target] [target...]
# Targets: fuzz_units fuzz_csv_convert fuzz_xy fuzz_experiment (default: all four).
# Each run starts from the committed seeds (tests/fuzz/corpus/<target>, read only) and the corpus
# grown by earlier runs (build/fuzz/corpus/<target>). libFuzzer runs in fork mode with
# -ignore_crashes, so that one problem does not end the run: every crash, timeout or
# out-of-memory leaves its input in build/fuzz/artifacts/<target>/ (replay:
# build/fuzz/tests/fuzz/<target> FILE). Logs: build/fuzz/logs/<target>.log.
# Exit status: 0 if no target found anything.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-150}"
shift || true
targets=("$@")
if ((${#targets[@]} == 0)); then targets=(fuzz_units fuzz_csv_convert fuzz_xy fuzz_experiment); fi

cmake -S . -B build/fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DUPHILL_FUZZ=ON > /dev/null
cmake --build build/fuzz -j"${UPHILL_JOBS:-2}" --target "${targets[@]}"

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# fuzz_experiment writes its two files per input into a folder under TMPDIR: give the run its own
# TMPDIR, in memory where possible, removed at the end (fork-mode workers exit without cleaning).
base="${TMPDIR:-}"
if [[ -z "$base" && -d /dev/shm && -w /dev/shm ]]; then base=/dev/shm; fi
TMPDIR=$(mktemp -d "${base:-/tmp}/uphill-fuzz.XXXXXX")
export TMPDIR
trap 'rm -rf "$TMPDIR"' EXIT
status=0
for t in "${targets[@]}"; do
  mkdir -p "build/fuzz/corpus/$t" "build/fuzz/artifacts/$t" build/fuzz/logs
  log="build/fuzz/logs/$t.log"
  before=$(ls "build/fuzz/artifacts/$t" | wc -l)
  echo "== $t: ${seconds} s (log: $log)"
  "build/fuzz/tests/fuzz/$t" "build/fuzz/corpus/$t" "tests/fuzz/corpus/$t" \
    -dict="tests/fuzz/$t.dict" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -max_len=4096 -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -artifact_prefix="build/fuzz/artifacts/$t/" > "$log" 2>&1 || true
  # The last status line: "#<executions>: cov: … exec/s <n> oom/timeout/crash: a/b/c time: …".
  grep -E '^#[0-9]+: cov:' "$log" | tail -1 || true
  found=$(($(ls "build/fuzz/artifacts/$t" | wc -l) - before))
  if ((found > 0)); then
    echo "$t: FOUND $found problem input(s) in build/fuzz/artifacts/$t/ (see $log)"
    status=1
  else
    echo "$t: nothing found"
  fi
done
exit $status
