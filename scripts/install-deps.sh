#!/usr/bin/env bash
# Installs every Debian 12 package uphill needs to build and test (run as root).
# The README's two Quick-start commands and .ci/run all go through this one script.
#   bash scripts/install-deps.sh          build + test dependencies
#   bash scripts/install-deps.sh --bench  also NumPy/SciPy for the benchmarks' comparisons
#   bash scripts/install-deps.sh --package  also debootstrap, for scripts/test-deb.sh
set -euo pipefail

packages=(
  g++ cmake ninja-build ccache pkg-config
  libeigen3-dev libceres-dev nlohmann-json3-dev libgtest-dev libcli11-dev libboost-dev
  libcsv-dev libfast-float-dev gnuplot-nox
  libcpp-httplib-dev chromium
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-videoio-dev
  libopencv-calib3d-dev
  # dpkg-shlibdeps for `cpack -G DEB`; man for the test of the installed manual pages
  dpkg-dev man-db
  # the Python module (python/): pybind11, Python's headers, NumPy; its tests (pytest) and the
  # example's figure (docs/python-example.py, tested too)
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
  librandom123-dev povray ffmpeg
  # XXH3, the content hash of the experiment's video cache (data/README.md)
  libxxhash-dev
)
# The browser test of `uphill serve` (tests/e2e) runs on node + npm and Debian's chromium. A
# machine that already has Node (e.g. a newer one from elsewhere) keeps it: Debian's npm would
# conflict with it.
if ! command -v node > /dev/null 2>&1; then
  packages+=(nodejs npm)
fi
for option in "$@"; do
  case "$option" in
    --bench) packages+=(python3-numpy python3-scipy python3-statsmodels python3-opencv) ;;
    --package) packages+=(debootstrap) ;;
    *) echo "install-deps: unknown option '$option' (--bench, --package)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
