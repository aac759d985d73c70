#!/usr/bin/env bash
# Configures and builds one flavour of uphill into build/<flavour>.
#   bash scripts/build.sh release    optimised build (the programs you run)
#   bash scripts/build.sh sanitize   AddressSanitizer + UndefinedBehaviorSanitizer build
set -euo pipefail
cd "$(dirname "$0")/.."
flavour="${1:-release}"
case "$flavour" in
  release) flags=(-DCMAKE_BUILD_TYPE=Release) ;;
  # -O1 -g1 (line tables only): enough for the sanitizers' reports, and cheaper to compile than
  # -O2 -g over the Ceres/Eigen/OpenCV templates (cold, 2 cores: 11 min for the whole tree).
  sanitize) flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
                   -DUPHILL_SANITIZE=ON) ;;
  *) echo "build.sh: unknown flavour '$flavour' (release|sanitize)" >&2; exit 2 ;;
esac
# ccache keyed on paths relative to the checkout, so a fresh clone elsewhere reuses the cache.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
cmake -S . -B "build/$flavour" -G Ninja "${flags[@]}" > /dev/null
cmake --build "build/$flavour" -j"${UPHILL_JOBS:-2}"
