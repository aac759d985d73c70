#!/usr/bin/env bash
# Keeps the documentation honest as code moves: every repository path a document names, every
# relative link it makes, every GoogleTest name it cites, and every `docs/physics.md "Section"`
# that a source comment cites must exist. Truth comes from the file tree and the test sources,
# not from the documents themselves.
#   bash tests/doc_references_test.sh [REPOSITORY_ROOT]
# Checked documents: README.md, docs/*.md, data/README.md, calibration/README.md.
#   - `path` in backticks, when it starts with a top-level folder of the repository (src/, tools/,
#     tests/, data/, calibration/, scripts/, docs/, packaging/) and holds no wildcard, placeholder
#     or space: the file or folder must exist.
#   - [text](target) links that are not URLs: the target, relative to the document, must exist.
#   - `Suite.Name` in backticks: a TEST, TEST_F or TEST_P (Suite, Name) must exist under tests/.
# Exit status: 0 when everything resolves, 1 otherwise (each miss printed as FILE: what).
set -uo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root" || exit 1

docs=(README.md data/README.md calibration/README.md)
for f in docs/*.md; do [[ -e "$f" ]] && docs+=("$f"); done

misses=0
miss() {
  echo "$1: $2"
  misses=$((misses + 1))
}

for doc in "${docs[@]}"; do
  [[ -f "$doc" ]] || { miss "$doc" "document missing"; continue; }
  dir=$(dirname "$doc")
  # Backticked spans (one line each; spans do not cross lines in these documents).
  while IFS= read -r span; do
    span="${span#\`}"
    span="${span%\`}"
    if [[ "$span" =~ ^(src|tools|tests|data|calibration|scripts|docs|packaging)/[A-Za-z0-9_./+-]*$ ]]; then
      [[ -e "$span" ]] || miss "$doc" "names missing path $span"
    elif [[ "$span" =~ ^([A-Z][A-Za-z0-9]*)\.([A-Z][A-Za-z0-9_]*)$ ]]; then
      suite="${BASH_REMATCH[1]}"
      name="${BASH_REMATCH[2]}"
      grep -rqE "TEST(_F|_P)?\($suite, *$name\)" tests --include='*.cpp' ||
        miss "$doc" "cites missing test $span"
    fi
  done < <(grep -o '`[^`]*`' "$doc")
  # Relative links [text](target).
  while IFS= read -r link; do
    target="${link#](}"
    target="${target%)}"
    target="${target%%#*}"
    [[ -z "$target" || "$target" =~ ^[a-z]+: ]] && continue
    [[ -e "$dir/$target" ]] || miss "$doc" "links missing $target"
  done < <(grep -oE '\]\([^)[:space:]]+\)' "$doc")
done

# Source comments cite the physics by section: docs/physics.md "Energy".
if [[ -f docs/physics.md ]]; then
  while IFS= read -r citation; do
    section="${citation#docs/physics.md \"}"
    section="${section%\"}"
    grep -qxF "## $section" docs/physics.md || miss "docs/physics.md" "has no section \"$section\" (cited in the code)"
  done < <(grep -rhoE --exclude=doc_references_test.sh 'docs/physics\.md "[^"]+"' src tools tests 2> /dev/null | sort -u)
fi

if ((misses > 0)); then
  echo "$misses broken reference(s)"
  exit 1
fi
echo "all references resolve (${#docs[@]} documents)"
