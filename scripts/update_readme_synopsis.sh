#!/bin/sh
# Rewrites README.md's synopsis of `transgi render` from `transgi render --help`
# (both are made from the option declarations in modules/transgi/cli/option_specs.cpp;
# the test cli.readme_render_synopsis fails while they differ).
# usage: scripts/update_readme_synopsis.sh [path/to/transgi]
set -eu
cd "$(dirname "$0")/.."
tool=${1:-./build/release/modules/transgi/transgi}
help=$(mktemp)
trap 'rm -f "$help" README.md.tmp' EXIT
"$tool" render --help > "$help"
awk -v help="$help" '
  /^<!-- begin: transgi render --help -->$/ { print; print "```"; while ((getline line < help) > 0) print line; print "```"; skip = 1; next }
  /^<!-- end: transgi render --help -->$/ { skip = 0 }
  !skip { print }
' README.md > README.md.tmp
mv README.md.tmp README.md
