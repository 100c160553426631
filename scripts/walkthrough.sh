#!/usr/bin/env bash
# Runs the README's walkthrough as written: every ```sh block between the heading "## Walkthrough" and
# the next "## " heading, in order, as one bash script under `set -euo pipefail`, in a fresh folder
# that holds only a link to the repository's assets/ (so the blocks' paths are those a reader types
# at the repository root), with the given tetrasand first on PATH. Any failing command fails it.
#   scripts/walkthrough.sh BIN_DIR [README]    (ctest: Readme.WalkthroughRunsAsWritten)
#   scripts/walkthrough.sh --print [README]     only print the extracted script
# About a minute on 2 cores with llvmpipe; the walkthrough's counts and duration are chosen for that.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
usage() { echo "usage: scripts/walkthrough.sh BIN_DIR [README] | --print [README]" >&2; exit 2; }
[ $# -ge 1 ] || usage
readme=${2:-$root/README.md}
[ -f "$readme" ] || { echo "walkthrough: $readme: no such file" >&2; exit 1; }

# The section's ```sh blocks, fences left out; other fences (```toml, ```text) are not run.
extract() {
  awk '
    /^## / { in_section = ($0 ~ /^## Walkthrough/) ; next }
    in_section && /^```sh$/ { in_block = 1; next }
    in_block && /^```$/ { in_block = 0; print ""; next }
    in_section && in_block { print }
  ' "$readme"
}
script=$(extract)
if [ -z "${script//[[:space:]]/}" ]; then
  echo "walkthrough: $readme has no \`\`\`sh block under a \"## Walkthrough\" heading" >&2; exit 1
fi
if [ "$1" = "--print" ]; then printf '%s\n' "$script"; exit 0; fi

bin=$(cd "$1" && pwd) || { echo "walkthrough: $1: no such folder" >&2; exit 1; }
[ -x "$bin/tetrasand" ] || { echo "walkthrough: $bin/tetrasand: not an executable" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ln -s "$root/assets" "$work/assets"
printf '%s\n' "$script" > "$work/walkthrough.sh"
cd "$work"
start=$SECONDS
# -x shows each command as it runs, so a failure names the line of the README that broke.
PATH="$bin:$PATH" bash -euo pipefail -x ./walkthrough.sh
echo "walkthrough: every command of $readme's walkthrough ran ($((SECONDS - start)) s)"
