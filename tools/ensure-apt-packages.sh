#!/usr/bin/env bash
# Install the given Debian packages if (and only if) some are not installed.
# A machine that already has them all runs one dpkg-query and nothing else:
# no `apt-get update`, no root needed.
set -euo pipefail

# Packages whose dpkg status is "ii" (wanted: install, current: installed).  Anything
# else -- unknown, removed ("rc"), half-configured -- counts as missing.
installed=$(dpkg-query -W -f='${Package} ${db:Status-Abbrev}\n' "$@" 2>/dev/null \
            | awk '$2 == "ii" { print $1 }' || true)
missing=()
for pkg in "$@"; do
    grep -qxF -- "$pkg" <<<"$installed" || missing+=("$pkg")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo ">>> Debian packages missing: ${missing[*]}"
sudo=()
if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "error: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
    sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
"${sudo[@]}" apt-get install -y -q "${missing[@]}"
