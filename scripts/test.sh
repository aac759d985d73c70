#!/usr/bin/env bash
# Quick start, second command: installs the dependencies, builds, and runs every test twice,
# in the optimised build and in the AddressSanitizer + UndefinedBehaviorSanitizer build.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
passed=0
failed=0
for flavour in release sanitize; do
  echo "== $flavour build"
  bash scripts/build.sh "$flavour"
  log="build/$flavour/ctest.log"
  status=0
  ctest --test-dir "build/$flavour" --output-on-failure -j2 --timeout 600 | tee "$log" || status=$?
  line=$(grep -E "tests passed, [0-9]+ tests failed out of [0-9]+" "$log" | tail -1)
  total=$(sed -E 's/.*out of ([0-9]+).*/\1/' <<< "$line")
  bad=$(sed -E 's/.*passed, ([0-9]+) tests failed.*/\1/' <<< "$line")
  passed=$((passed + total - bad))
  failed=$((failed + bad))
  if ((status != 0)) && ((bad == 0)); then failed=$((failed + 1)); fi
done
echo "all builds: $passed passed, $failed failed"
((failed == 0))
