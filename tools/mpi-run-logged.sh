#!/usr/bin/env bash
# Run a command on NP MPI ranks with readable output and a reliable exit status.
#
#   tools/mpi-run-logged.sh NP LOGDIR LAUNCHER [LAUNCHER-ARGS...] -- COMMAND [ARGS...]
#
# e.g. tools/mpi-run-logged.sh 2 .venv/mpi-logs mpirun --oversubscribe -- .venv/bin/python -m pytest
#
# * Rank 0 prints to the terminal (and to LOGDIR/rank0.log); every other rank writes only to
#   LOGDIR/rank<N>.log, so two pytest sessions never interleave on screen.  Afterwards one
#   summary line (the last line of its log) is printed per other rank, or its whole log if
#   it failed.
# * Each rank's wrapper records the command's exit status in LOGDIR/rank<N>.rc and then
#   exits 0: Open MPI's mpirun aborts the whole job as soon as one rank exits non-zero,
#   which would cut off the other ranks' reports.  The statuses are then checked here: exit 0 only if the launcher and every rank succeeded; otherwise exit
#   with the first failing rank's status (pytest's 1, 5 = no tests collected, ... are kept).
# * "{rank}" in COMMAND's arguments is replaced by the rank (e.g. a per-rank --basetemp).
# * Works with Open MPI (OMPI_COMM_WORLD_RANK) and MPICH/hydra (PMI_RANK).
set -uo pipefail

self=$(readlink -f "${BASH_SOURCE[0]}")

if [[ ${1:-} == --rank ]]; then            # ---- inside the launcher: one rank ----
    logdir=$2; shift 2
    rank=${OMPI_COMM_WORLD_RANK:-${PMI_RANK:-${PMIX_RANK:-}}}
    if [[ -z $rank ]]; then
        echo "mpi-run-logged: cannot tell the MPI rank (not under mpirun/mpiexec?)" >&2
        exit 97
    fi
    cmd=("${@//\{rank\}/$rank}")
    if [[ $rank == 0 ]]; then
        "${cmd[@]}" 2>&1 | tee "$logdir/rank0.log"
        rc=${PIPESTATUS[0]}
    else
        "${cmd[@]}" >"$logdir/rank$rank.log" 2>&1
        rc=$?
    fi
    echo "$rc" >"$logdir/rank$rank.rc"
    exit 0
fi

# ---- outside: launch and check ----
if [[ $# -lt 5 ]]; then
    echo "usage: $0 NP LOGDIR LAUNCHER [ARGS...] -- COMMAND [ARGS...]" >&2
    exit 2
fi
np=$1 logdir=$2; shift 2
launcher=()
while [[ $# -gt 0 && $1 != -- ]]; do launcher+=("$1"); shift; done
[[ ${1:-} == -- ]] && shift
if [[ ${#launcher[@]} -eq 0 || $# -eq 0 ]]; then
    echo "usage: $0 NP LOGDIR LAUNCHER [ARGS...] -- COMMAND [ARGS...]" >&2
    exit 2
fi

rm -rf "$logdir"
mkdir -p "$logdir"
logdir=$(readlink -f "$logdir")

"${launcher[@]}" -n "$np" bash "$self" --rank "$logdir" "$@"
launcher_rc=$?

status=0
for ((r = 0; r < np; r++)); do
    log="$logdir/rank$r.log"
    if [[ -f $logdir/rank$r.rc ]]; then
        rc=$(<"$logdir/rank$r.rc")
    else
        rc=""                           # killed, MPI_Abort-ed, or never started
    fi
    if [[ $rc == 0 ]]; then
        ((r > 0)) && echo "rank $r: $(tail -n 1 "$log" 2>/dev/null)"
        continue
    fi
    echo "!!! rank $r FAILED (exit status ${rc:-unknown, no status recorded})"
    if ((r > 0)) && [[ -s $log ]]; then
        echo "----- output of rank $r ($log) -----"
        cat "$log"
        echo "----- end of rank $r -----"
    fi
    ((status == 0)) && status=${rc:-1}
done
if ((launcher_rc == 124)) && [[ ${launcher[0]} == timeout ]]; then
    echo "!!! TIMED OUT: the MPI job was killed by '${launcher[*]:0:3}'"
    status=124
elif ((launcher_rc != 0)); then
    echo "!!! ${launcher[0]} exited with status $launcher_rc"
    ((status == 0)) && status=$launcher_rc
fi
exit "$status"
