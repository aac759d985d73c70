#!/usr/bin/env bash
# The Debian package on a fresh Debian 12: builds it (`cpack -G DEB` in build/release), bootstraps
# a minimal Debian 12 (bookworm) with Debian's debootstrap, installs the package there with
# `apt install ./uphill_*.deb` (Debian's mirror resolves its dependencies) and runs the installed
# program from another folder: --version, convert, fit, report (gnuplot), the manual pages, the
# bash completion, the systemd user unit, and the Python module of python3-uphill.
#
#   sudo bash scripts/test-deb.sh            (root: debootstrap, chroot and mount need it)
#
# Manual / optional CI step, not part of scripts/test.sh: it needs the network to the Debian
# mirror and takes minutes (the first run bootstraps Debian and downloads ~430 packages; the
# bootstrapped base and the downloaded packages are kept in $UPHILL_DEB_TEST_CACHE, default
# /var/tmp/uphill-deb-test, and every run starts from a fresh copy of the base).
set -euo pipefail
cd "$(dirname "$0")/.."
mirror=${UPHILL_DEBIAN_MIRROR:-http://deb.debian.org/debian}
cache=${UPHILL_DEB_TEST_CACHE:-/var/tmp/uphill-deb-test}
[[ $(id -u) -eq 0 ]] || { echo "test-deb: run as root (debootstrap, chroot, mount)" >&2; exit 2; }
command -v debootstrap > /dev/null || { echo "test-deb: needs debootstrap: bash scripts/install-deps.sh --package" >&2; exit 2; }

echo "== building the package"
bash scripts/build.sh release
rm -f build/release/uphill*.deb
(cd build/release && cpack -G DEB > cpack.log) || { cat build/release/cpack.log; exit 1; }
debs=(build/release/*.deb)
for deb in "${debs[@]}"; do dpkg-deb -f "$deb" Package Version Depends; done

base=$cache/base
if [[ ! -x $base/usr/bin/apt-get ]]; then
  echo "== bootstrapping a minimal Debian 12 into $base (once)"
  rm -rf "$base"
  mkdir -p "$cache"
  debootstrap --variant=minbase bookworm "$base" "$mirror" > "$cache/debootstrap.log" 2>&1 ||
    { tail -20 "$cache/debootstrap.log"; exit 1; }
fi

root=$(mktemp -d "$cache/run-XXXXXX")
cleanup() {
  for m in var/cache/apt/archives dev/pts dev proc; do
    if mountpoint -q "$root/$m"; then umount -l "$root/$m"; fi
  done
  rm -rf --one-file-system "$root"  # never into a mount still attached
}
trap cleanup EXIT
cp -a "$base/." "$root/"
# The sources of a fresh Debian 12 install: the release, its updates and security.
cat > "$root/etc/apt/sources.list" << EOF
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
# Downloaded packages are kept between runs (the system itself is fresh every time).
mkdir -p "$cache/archives/partial"
mount --bind "$cache/archives" "$root/var/cache/apt/archives"
mkdir -p "$root/tmp/debs"
cp "${debs[@]}" "$root/tmp/debs/"

echo "== apt install ./uphill_*.deb on the fresh system"
chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive LANG=C.UTF-8 \
  bash -euo pipefail -c '
    apt-get update -qq
    apt-get install -y -qq /tmp/debs/*.deb > /tmp/apt.log || { tail -30 /tmp/apt.log; exit 1; }
    apt-get install -y -qq passwd > /dev/null  # useradd, part of every real install, not of minbase
    grep -E "^(Setting up|Unpacking) uphill" /tmp/apt.log
    echo "installed packages: $(dpkg-query -W -f "\${binary:Package}\n" | wc -l)"
  '

echo "== the installed program, as a user in their home folder"
cat > "$root/tmp/as-user.sh" << 'EOF'
set -euo pipefail
cd ~
command -v uphill
uphill --version
uphill convert --body spheroid --a 15.875mm --b 25.4mm --L 1165mm --H 300mm --D 120mm --mu 0.05 > one.txt
head -8 one.txt
uphill convert --batch /usr/share/uphill/data/convert_batch.csv --csv --mc-trials 1000 > batch.csv
head -3 batch.csv
uphill fit /usr/share/uphill/data/series2-fixed-L --mc-trials 1000 > fit.txt
head -4 fit.txt
uphill report /usr/share/uphill/data/series2-fixed-L -o report --mc-trials 1000
test -s report/report.html && test -s report/fit_y_vs_x.png
uphill paper-figures -o figures > /dev/null && test -s figures/series2-fixed-L/fit_y_vs_x.svg
man uphill-convert | grep -q -- --batch && echo "man uphill-convert: ok"
source /usr/share/bash-completion/completions/uphill
COMP_WORDS=(uphill c) COMP_CWORD=1
_uphill_complete
echo "completion of 'uphill c': ${COMPREPLY[*]}"
if dpkg-query -W python3-uphill > /dev/null 2>&1; then
  python3 - << 'PY'
import numpy as np
import uphill
print("python3-uphill:", uphill.__version__, uphill.__file__, uphill.kernel())
theta, alpha, x_eq = uphill.convert_apparatus(np.array([1.165]), np.array([0.3]), np.array([0.12]), "15.875 mm", "25.4 mm")
print("X =", x_eq[0], "m")
analysis = uphill.analyse_experiment("/usr/share/uphill/data/series2-fixed-L", mc_trials=1000)
print("York slope of the sample experiment:", analysis.fits["york"].slope)
PY
fi
EOF
chmod 755 "$root/tmp/as-user.sh"
chroot "$root" /usr/bin/env -i PATH=/usr/bin:/bin LANG=C.UTF-8 bash -euo pipefail -c '
  /usr/sbin/useradd --create-home --shell /bin/bash lab
  su lab -c "bash /tmp/as-user.sh"
'

echo "== the systemd user unit (systemd-analyze verify)"
chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive bash -euo pipefail -c '
  apt-get install -y -qq --no-install-recommends systemd > /dev/null
  systemd-analyze verify /usr/share/systemd/user/uphill-serve.service && echo "uphill-serve.service: verified"
'
echo "test-deb: ${debs[*]##*/} installed and ran on a fresh Debian 12"
