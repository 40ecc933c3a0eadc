#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The style checks (run by `tools/dev.sh test`; needs the venv of `tools/dev.sh setup`):
#   ruff check, ruff format --check   tools/ Python (configuration: tools/pyproject.toml)
#   clang-format --dry-run             the C files listed in tools/clang-format-files.txt
#                                      (configuration: /.clang-format)
#   tools/long_functions.py            no more than LONG_FUNCTIONS_MAX functions over 80 lines
#                                      in the production code (cut a new one into named steps)
# Fix with `.venv/bin/ruff check --fix tools && .venv/bin/ruff format tools` and
# `.venv/bin/clang-format -i FILE`.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bin=.venv/bin
status=0
LONG_FUNCTIONS_MAX=5
"$bin/ruff" check --no-cache tools || status=1
"$bin/ruff" format --check --no-cache tools || status=1
mapfile -t files < <(grep -v '^\s*\(#\|$\)' tools/clang-format-files.txt)
for f in "${files[@]}"; do
    [ -f "$f" ] || { echo "tools/clang-format-files.txt: no file $f"; status=1; continue; }
done
"$bin/clang-format" --dry-run -Werror "${files[@]}" || status=1
"$bin/python" tools/long_functions.py --max-count "$LONG_FUNCTIONS_MAX" | tail -n 1 || status=1
if [ "$status" -eq 0 ]; then
    echo "style: ruff, clang-format (${#files[@]} C files) and function lengths clean"
fi
exit "$status"
