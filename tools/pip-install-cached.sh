#!/usr/bin/env bash
# `pip install` into a venv from a persistent local wheelhouse, so that a fresh venv (a fresh
# clone in CI) downloads nothing that an earlier install already downloaded.
#
#   tools/pip-install-cached.sh WHEELHOUSE PYTHON [PIP-INSTALL-ARGS...]
#
# e.g. tools/pip-install-cached.sh ~/.cache/rwall_fem/wheels/0.5 .venv/bin/python \
#          -c .venv/constraints.txt -e '.[test]'
#
# Why: pip's own HTTP cache (~/.cache/pip) stays empty when the index is reached through a
# proxy that sends no caching headers, so every new venv would download every wheel again.
#
# The wheels live in WHEELHOUSE/py<X.Y> (<X.Y>: PYTHON's version, so two interpreters never
# evict each other's wheels).  PIP-INSTALL-ARGS are requirements, `-c FILE`, `-r FILE` and
# `-e DIR[extras]`.
#
#  1. pip install --no-index --find-links WHEELHOUSE ARGS.  If the wheelhouse has everything
#     (the usual case), that is all: nothing is downloaded, the index is never asked.
#  2. Otherwise (first install, a new dependency in pyproject.toml, another Python, ...):
#     refresh the wheelhouse with `pip wheel -w`, from the index, for ARGS with each
#     `-e DIR[extras]` replaced by what DIR needs (tools/pyproject-requirements.py: build
#     requirements such as setuptools, which the editable install builds with, dependencies,
#     extras), plus `wheel`.  pip reuses the wheels already there (by file name) and downloads
#     only the others; an sdist is built into a wheel once.  Then wheels no longer picked are
#     pruned and step 1 runs again.
#  3. If that fails as well (e.g. no network), a plain `pip install ARGS` as a last resort.
#
# An empty WHEELHOUSE means: no wheelhouse, plain `pip install ARGS`.  Concurrent runs on
# the same wheelhouse are serialised (flock on WHEELHOUSE/py<X.Y>.lock).
#
# pip byte-compiles what it installs one file at a time, which for VTK, matplotlib, ... takes
# as long as the unpacking; so pip runs with --no-compile and `compileall -j 0` then compiles
# the venv's site-packages on every core.  (Skipping compilation altogether would make every
# later import slower, and forever where PYTHONDONTWRITEBYTECODE is set.)
set -euo pipefail

if [[ $# -lt 2 ]]; then
    echo "usage: $0 WHEELHOUSE PYTHON [PIP-INSTALL-ARGS...]" >&2
    exit 2
fi
wh=$1 py=$2; shift 2
pip=("$py" -m pip)

# Byte-compile the venv's own site-packages (not the system's) in parallel.  Like pip, ignore
# files that do not compile (templates, Python-2 leftovers in some packages).
compile_venv() {
    local site
    site=$("$py" -c 'import sysconfig; print(sysconfig.get_path("purelib"))')
    "$py" -W ignore -m compileall -q -j 0 "$site" >/dev/null 2>&1 || true
}

if [[ -z $wh ]]; then
    "${pip[@]}" install -q --no-compile "$@"
    compile_venv
    exit 0
fi

here=$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")
wh="$wh/py$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
mkdir -p "$wh"
if command -v flock >/dev/null; then
    exec 9>"$wh.lock"
    flock 9
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# ---- 1. offline, from the wheelhouse alone ----
install_offline() {
    "${pip[@]}" install -q --no-compile --no-index --find-links "$wh" "$@" 2>"$tmp/offline.err"
}
if install_offline "$@"; then
    compile_venv
    echo "    (installed from the wheelhouse $wh; nothing downloaded)"
    exit 0
fi
why=$(grep -E '^\s*ERROR:' "$tmp/offline.err" | tail -n 1 | sed -E 's/^\s*ERROR: //' || true)
echo ">>> wheelhouse $wh cannot satisfy the requirements${why:+ ($why)}: refreshing it from the index"

# ---- 2. refresh the wheelhouse, prune it, and install offline again ----
# What to put in the wheelhouse: the arguments, with `-e DIR[extras]` expanded.
refresh() {
    local reqs=() arg
    while [[ $# -gt 0 ]]; do
        arg=$1; shift
        case $arg in
            -e | --editable) mapfile -t -O "${#reqs[@]}" reqs < <("$py" "$here/pyproject-requirements.py" "$1"); shift ;;
            --editable=*)    mapfile -t -O "${#reqs[@]}" reqs < <("$py" "$here/pyproject-requirements.py" "${arg#*=}") ;;
            -e?*)            mapfile -t -O "${#reqs[@]}" reqs < <("$py" "$here/pyproject-requirements.py" "${arg#-e}") ;;
            *)               reqs+=("$arg") ;;
        esac
    done
    # process substitution hides the helper's exit status: check that it listed something
    [[ ${#reqs[@]} -gt 0 ]] || return 1
    reqs+=(wheel)   # older setuptools ask for it to build an editable install

    # Only what is not in $wh yet is downloaded (pip looks in the -w directory first).
    "${pip[@]}" wheel -q -w "$wh" "${reqs[@]}" || return 1

    # Prune: keep the wheels an install of the same requirements from $wh alone picks.
    "${pip[@]}" install -q --dry-run --ignore-installed --no-index --find-links "$wh" \
        --report "$tmp/report.json" "${reqs[@]}" || return 1
    "$py" - "$wh" "$tmp/report.json" <<'EOF'
import json, sys
from pathlib import Path
from urllib.parse import unquote, urlparse
wh, report = Path(sys.argv[1]), json.loads(Path(sys.argv[2]).read_text())
keep = {Path(unquote(urlparse(i["download_info"]["url"]).path)).name for i in report["install"]}
for f in wh.iterdir():
    if f.is_file() and f.name not in keep:
        f.unlink()
EOF
}
if refresh "$@" && install_offline "$@"; then
    compile_venv
    echo "    (wheelhouse $wh refreshed: $(du -sh "$wh" | cut -f1); installed from it)"
    exit 0
fi
[[ -s $tmp/offline.err ]] && cat "$tmp/offline.err" >&2

# ---- 3. last resort ----
echo ">>> WARNING: could not install from the wheelhouse $wh; plain pip install from the index"
"${pip[@]}" install -q --no-compile "$@"
compile_venv
