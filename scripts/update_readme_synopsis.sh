#!/bin/sh
# Rewrites README.md's synopses of `transgi render` and `transgi bench-frame` from
# their `--help` (both are made from the option declarations in
# modules/transgi/cli/option_specs.cpp; the tests cli.readme_*_synopsis fail while they differ).
# usage: scripts/update_readme_synopsis.sh [path/to/transgi]
set -eu
cd "$(dirname "$0")/.."
tool=${1:-./build/release/modules/transgi/transgi}
help=$(mktemp)
trap 'rm -f "$help" README.md.tmp' EXIT
for command in render bench-frame; do
  "$tool" "$command" --help > "$help"
  awk -v help="$help" -v begin="<!-- begin: transgi $command --help -->" -v end="<!-- end: transgi $command --help -->" '
    $0 == begin { print; print "```"; while ((getline line < help) > 0) print line; print "```"; skip = 1; next }
    $0 == end { skip = 0 }
    !skip { print }
  ' README.md > README.md.tmp
  mv README.md.tmp README.md
done
