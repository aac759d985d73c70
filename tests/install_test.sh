#!/usr/bin/env bash
# The installed uphill, as a user meets it: `cmake --install` of this build into a temporary
# prefix, then, from a folder outside the source and build trees, the installed program, its data,
# its manual pages and its bash completion.
#   install_test.sh BUILD_DIR BUILT_PROGRAM VERSION
# Truths: the version is CMake's project version; the installed program's output must be the
# built program's, byte for byte, on the same input; the manual pages and the completion must
# list what the program's own --help lists (CLI11's help formatter, a separate code path from the
# generator in tools/uphill/self_documentation.cpp).
set -euo pipefail
build_dir=$1
built=$2
version=$3

work=$(mktemp -d /tmp/uphill-install-test-XXXXXX)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
fail() { echo "install_test: $*" >&2; exit 1; }

cmake --install "$build_dir" --prefix "$prefix" > "$work/install.log" || { cat "$work/install.log"; fail "cmake --install failed"; }
uphill=$prefix/bin/uphill
[[ -x $uphill ]] || fail "no $uphill"
mkdir "$work/elsewhere"
cd "$work/elsewhere"
# The build tree must not be reachable: only the prefix.
export PATH=$prefix/bin:/usr/bin:/bin

# --- the program and its data ---
got=$(uphill --version)
[[ $got == "uphill $version" ]] || fail "--version printed '$got', expected 'uphill $version'"

data=$prefix/share/uphill/data
[[ -f $data/convert_batch.csv && -f $data/series2-fixed-L/measurements.csv ]] || fail "sample data not installed in $data"
uphill convert --batch "$data/convert_batch.csv" --json --mc-trials 1000 > installed.json
"$built" convert --batch "$data/convert_batch.csv" --json --mc-trials 1000 > built.json
cmp -s installed.json built.json || fail "installed and built convert differ on convert_batch.csv"
grep -q '"x_eq"' installed.json || fail "convert printed no x_eq"
uphill fit "$data/series2-fixed-L" --json --mc-trials 1000 > fit.json
grep -q '"york"' fit.json || fail "fit of the installed sample experiment has no York fit"

# paper-figures without --data finds the installed sample experiments (PREFIX/share/uphill).
uphill paper-figures -o figures > /dev/null
[[ -f figures/series2-fixed-L/fit_y_vs_x.svg ]] || fail "paper-figures did not find the installed sample data"

# A vision command (OpenCV; run by a sibling executable when the program is split).
uphill calibrate target --cols 9 --rows 6 --square 20mm -o board.svg > /dev/null
grep -q "<svg" board.svg || fail "calibrate target wrote no SVG"

# The docs and the service files.
for f in share/doc/uphill/README.md share/doc/uphill/data/README.md share/doc/uphill/calibration/README.md \
         share/systemd/user/uphill-serve.service share/applications/uphill-serve.desktop \
         share/uphill/tools/bench/fit_peers.py; do
  [[ -f $prefix/$f ]] || fail "not installed: $f"
done
grep -q '^ExecStart=uphill serve .*--host 127.0.0.1' "$prefix/share/systemd/user/uphill-serve.service" ||
  fail "the user unit must serve on loopback"

# --- the manual pages ---
mandir=$prefix/share/man/man1
# The subcommands of a command, from its --help ("Subcommands:" section of CLI11's formatter).
subcommands() { uphill "$@" --help | sed -n '/^Subcommands:/,$p' | sed -nE 's/^  ([a-z][a-z0-9-]*) .*/\1/p'; }
# The long flags of a command, from its --help (hidden flags are not shown there).
flags() { uphill "$@" --help | sed '/^Subcommands:/,$d' | grep -oE -- '--[A-Za-z][A-Za-z0-9-]*' | sort -u; }
pages=0
check_page() {  # the words of a command, e.g. calibrate scene
  local name page text
  name=$(IFS=-; echo "uphill${*:+-$*}")
  page=$mandir/$name.1.gz
  [[ -f $page ]] || fail "no manual page $name(1)"
  text=$(MANWIDTH=200 man -l "$page" 2> "$work/man.err") || fail "man -l $page failed: $(cat "$work/man.err")"
  [[ ! -s $work/man.err ]] || fail "man -l $page warned: $(cat "$work/man.err")"
  grep -q "^NAME" <<< "$text" || fail "$name(1) has no NAME section"
  local flag
  for flag in $(flags "$@"); do
    grep -qe "$flag" <<< "$text" || fail "$name(1) does not list $flag, which '$*' --help lists"
  done
  pages=$((pages + 1))
  local sub
  for sub in $(subcommands "$@"); do
    grep -qe "$name-$sub(1)" <<< "$text" || fail "$name(1) does not refer to $name-$sub(1)"
    check_page "$@" "$sub"
  done
}
check_page
installed_pages=$(find "$mandir" -name 'uphill*.1.gz' | wc -l)
((pages == installed_pages)) || fail "$installed_pages manual pages installed, $pages commands in --help"
MANPATH=$prefix/share/man man -w uphill-convert > /dev/null || fail "man does not find uphill-convert by name"

# --- bash completion ---
completion=$prefix/share/bash-completion/completions/uphill
[[ -f $completion ]] || fail "no bash completion"
complete_words() {  # the words of a command line, the last one being completed
  bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _uphill_complete; printf "%s\n" "${COMPREPLY[@]}"' \
    _ "$completion" "$@"
}
expected=$(subcommands | sort | tr '\n' ' ')
got=$(complete_words uphill "" | sort | tr '\n' ' ')
[[ $got == "$expected" ]] || fail "completion of 'uphill ' gave '$got', expected '$expected'"
expected=$(subcommands calibrate | sort | tr '\n' ' ')
got=$(complete_words uphill calibrate "" | sort | tr '\n' ' ')
[[ $got == "$expected" ]] || fail "completion of 'uphill calibrate ' gave '$got', expected '$expected'"
got=$(complete_words uphill convert --bat)
[[ $got == "--batch" ]] || fail "completion of 'uphill convert --bat' gave '$got'"
got=$(complete_words uphill convert --body sphere --batch "$data/convert_b")
[[ $got == "$data/convert_batch.csv" ]] || fail "completion of a --batch file gave '$got'"

# --- the Python module, where Debian's python3 finds it under this prefix ---
if [[ -n ${UPHILL_PYTHON:-} ]]; then
  module_dir=$prefix/${UPHILL_PYTHON_INSTALL_DIR}
  ls "$module_dir"/uphill*.so > /dev/null 2>&1 || fail "no Python module in $module_dir"
  got=$(PYTHONPATH=$module_dir "$UPHILL_PYTHON" -c '
import sys, numpy as np, uphill
print(uphill.__version__)
t, a, x = uphill.convert_apparatus(np.array([1.165]), np.array([0.3]), np.array([0.12]), "15.875 mm", "25.4 mm")
one = uphill.convert_setting(body="spheroid", a="15.875mm", b="25.4mm", L="1165mm", H="300mm", D="120mm", mc_trials=1000)
print("same" if abs(one["x_eq"] / x[0] - 1) < 3e-15 else "differs")  # batch kernel vs Scene: a few ulp
print(uphill.analyse_experiment(sys.argv[1], mc_trials=1000).fits["york"].slope > 0)
' "$data/series2-fixed-L")
  [[ $got == "$version"$'\n'"same"$'\n'"True" ]] || fail "the installed Python module printed: $got"
  python_note=", and the Python module"
fi

echo "install_test: installed into $prefix: --version, convert, fit, paper-figures, calibrate target from another folder;" \
     "$pages manual pages render and list every flag; bash completion${python_note:-}"
