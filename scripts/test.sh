#!/usr/bin/env bash
# Quick start, second command: installs the dependencies, builds, and runs every test twice,
# in the optimised build and in the AddressSanitizer + UndefinedBehaviorSanitizer build.
# The last line counts the tests of both builds: `total: N passed, F failed, K skipped`. A
# skipped test counts as a failure too (the exit status is then 1), unless tests/optional-tests.txt
# names it with the reason it may not run on every machine: a green run means every test the
# README promises ran.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The names (regular expressions, one per line; # comments) of the tests that may skip.
optional=$(sed -e 's/#.*//' -e '/^[[:space:]]*$/d' tests/optional-tests.txt | awk '{print $1}' | paste -sd'|')
passed=0 failed=0 skipped=0 unexpected=()
for flavour in release sanitize; do
  echo "== $flavour build"
  bash scripts/build.sh "$flavour"
  log="build/$flavour/ctest.log"
  status=0
  ctest --test-dir "build/$flavour" --output-on-failure -j2 --timeout 600 | tee "$log" || status=$?
  # One line per test: "<i>/<n> Test #<k>: <name> ....   Passed" (or ***Skipped, ***Failed, …).
  results=$(grep -E '^ *[0-9]+/[0-9]+ +Test +#[0-9]+: ' "$log" || true)
  p=$(grep -cE ' Passed +[0-9.]+ sec' <<< "$results" || true)
  s=$(grep -cE '\*\*\*Skipped ' <<< "$results" || true)
  n=$(grep -cE . <<< "$results" || true)
  total=$(grep -oE 'tests failed out of [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$' || echo 0)
  # Tests that never started (a crash of ctest itself, a missing executable) count as failed.
  ((total > n)) && n=$total
  passed=$((passed + p))
  skipped=$((skipped + s))
  failed=$((failed + n - p - s))
  if ((status != 0)) && ((n - p - s == 0)); then failed=$((failed + 1)); fi
  while read -r name; do
    [[ -z "$name" ]] && continue
    if [[ -z "$optional" ]] || ! grep -qxE "$optional" <<< "$name"; then unexpected+=("$flavour:$name"); fi
  done < <(grep -E '\*\*\*Skipped ' <<< "$results" | sed -E 's/.*Test +#[0-9]+: ([^ ]+) .*/\1/')
done
if ((${#unexpected[@]} > 0)); then
  echo "skipped, though the README promises them (tests/optional-tests.txt lists the tests that may skip):"
  printf '  %s\n' "${unexpected[@]}"
fi
echo "total: $passed passed, $failed failed, $skipped skipped"
((failed == 0)) && ((${#unexpected[@]} == 0))
