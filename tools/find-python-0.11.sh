#!/usr/bin/env bash
# Print the interpreter to build the DOLFINx 0.11 venv with (dolfinx-solver-real needs
# Python >= 3.12), or print nothing if there is none.  Never fails.
#
# Order: newest pyenv 3.12.x, newest pyenv 3.13.x, then python3.12 / python3.13 on PATH.
# Only plain X.Y.Z pyenv versions count (no 3.12-dev, no free-threaded 3.13.0t).
# The path printed is the interpreter's real sys.executable (pyenv shims resolved).
set -uo pipefail

candidates=()
root=$(pyenv root 2>/dev/null || echo "${PYENV_ROOT:-$HOME/.pyenv}")
for minor in 12 13; do
    newest=$(ls -1 "$root/versions" 2>/dev/null | grep -E "^3\.$minor\.[0-9]+$" | sort -V | tail -n 1)
    [[ -n $newest ]] && candidates+=("$root/versions/$newest/bin/python3")
done
candidates+=(python3.12 python3.13)

for py in "${candidates[@]}"; do
    exe=$("$py" -c 'import sys; assert sys.version_info >= (3, 12); print(sys.executable)' 2>/dev/null) \
        && [[ -n $exe ]] && { echo "$exe"; exit 0; }
done
exit 0
