#!/usr/bin/env bash
# The structure checks CI runs before the tests (scripts/test.sh calls this first, so a
# violation fails in seconds): no function in src/ over 150 lines and no file over 1000
# (scripts/long_functions.py), no import circle between files or between modules
# (scripts/import_cycles.py). Run alone from anywhere in the checkout:
#
#   scripts/checks.sh          # both; exit 1 and say what failed
#   scripts/checks.sh SRC      # the same on another source tree (e.g. a scratch copy)
set -uo pipefail
cd "$(dirname "$0")/.."
src="${1:-src}"
failed=()
echo "== sizes: functions ≤ 150 lines, files ≤ 1000 lines in $src"
python3 scripts/long_functions.py "$src" || failed+=("sizes (scripts/long_functions.py): split the function or the file listed above by meaning")
echo "== import circles between files and between modules in $src"
python3 scripts/import_cycles.py "$src" || failed+=("import circles (scripts/import_cycles.py): see the hint above")
if [ ${#failed[@]} -gt 0 ]; then
    echo
    for f in "${failed[@]}"; do echo "error: structure check failed: $f" >&2; done
    exit 1
fi
echo "structure checks passed"
