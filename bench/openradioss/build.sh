#!/bin/bash
# Build OpenRadioss (starter + engine, gfortran, 1 thread) from a snapshot of its public
# sources, for bench/openradioss_timing.py. Usage: bash build.sh SRC [EXTLIB]
#   SRC: a checkout of github.com/OpenRadioss/OpenRadioss (checked with bd4557ba7);
#   EXTLIB: a checkout of github.com/OpenRadioss/OpenRadioss_extlib (checked with acb56d7,
#     its version 73), copied to SRC/extlib when SRC has none: the build would otherwise
#     download extlib.zip, and this machine has no network. Its static LAPACK may be absent
#     from a snapshot (a large file): Debian's (liblapack-dev, libblas-dev) takes its place.
#     Needs gfortran. The reader must first be built with SRC/extlib in place: Boost's
#     headers in /usr/include (1.74) do not match extlib's 1.70 library (a reader built
#     without extlib leaves undefined boost::filesystem symbols: rm -rf SRC/reader/cbuild_*).
# The starter links the open reader built from SRC/reader; two edits make them agree:
#  1. the starter writes format 2612 (its CODVERS) while the open reader stops at 2026:
#     the reader is taught 2612 the way upstream taught it 2026 (five places below);
#     without it the reader throws "CFG Kernel Not Loaded", which cfgreader_inc swallows,
#     and the starter dies in hm_messages with a segmentation fault (ERROR 760);
#  2. four entry points the starter calls are absent from the open reader (rigid parts
#     turned into rigid bodies, /ALE/STRUCTURED_MESH, a part's element check): stubs.c,
#     linked into the starter. No peer deck uses them. The engine is not touched.
# Takes about an hour on 2 cores (nice 19). Then: export
#   LD_LIBRARY_PATH=SRC/exec RAD_CFG_PATH=SRC/hm_cfg_files OMP_STACKSIZE=400m; ulimit -s unlimited
set -euo pipefail
SRC=$(realpath "$1"); HERE=$(dirname "$(realpath "$0")")
if [ ! -f "$SRC/extlib/EXTLIB_VERSION.json" ]; then
  [ $# -ge 2 ] || { echo "no $SRC/extlib: give a checkout of OpenRadioss_extlib as EXTLIB"; exit 1; }
  rm -rf "$SRC/extlib" && cp -r "$2/extlib" "$SRC/extlib" && cp "$2/EXTLIB_VERSION.json" "$SRC/extlib/"
  LAPACK=$SRC/extlib/lapack-3.10.0/lib_linux64_gf
  if [ ! -s "$LAPACK/liblapack.a" ]; then
    mkdir -p "$LAPACK" && T=$(mktemp -d) && mkdir "$T/l" "$T/b"
    (cd "$T/l" && ar x /usr/lib/x86_64-linux-gnu/lapack/liblapack.a)
    (cd "$T/b" && ar x /usr/lib/x86_64-linux-gnu/blas/libblas.a)
    rm -f "$LAPACK/liblapack.a" && ar rcs "$LAPACK/liblapack.a" "$T"/l/*.o "$T"/b/*.o && rm -rf "$T"
  fi
fi
K=$SRC/reader/source/cfgkernel/KERNEL
if ! grep -q FF_D00_2612 "$K/mv_file_format.h"; then
  sed -i 's/^\(\s*\)FF_D00_2026,$/&\n\1FF_D00_2612,/' "$K/mv_file_format.h"
  sed -i 's/^\(\s*\)myStrFileFormatMap\["radioss2026"\] = FF_D00_2026;$/&\n\1myStrFileFormatMap["radioss2612"] = FF_D00_2612;/' "$K/mv_file_format.cpp"
  sed -i 's/^\(\s*\)myFormat2VersionMap\[FF_D00_2026\]   = "radioss2026";$/&\n\1myFormat2VersionMap[FF_D00_2612]   = "radioss2612";/' "$K/mv_file_format.cpp"
  sed -i 's/^\(\s*\)myVersion2FormatMap\["radioss2026"\] = FF_D00_2026;$/&\n\1myVersion2FormatMap["radioss2612"] = FF_D00_2612;/' "$K/mv_file_format.cpp"
  sed -i 's/^\(\s*\)if (ff_id >= FF_D00_2026)\(\s*\)a_ff_p = getFileFormatPtr(FF_D00_2026);$/\1if (ff_id >= FF_D00_2612) a_ff_p = getFileFormatPtr(FF_D00_2612);\n\1if (a_ff_p == NULL \&\& ff_id >= FF_D00_2026) a_ff_p = getFileFormatPtr(FF_D00_2026);/' "$K/mv_descriptor.cpp"
  sed -i 's/versions = { "radioss2026",/versions = { "radioss2612", "radioss2026",/' "$K/mv_utils.cpp"
  sed -i 's/= "radioss2026:radioss2025:/= "radioss2612:radioss2026:radioss2025:/' "$K/cfg_kernel.cpp"
  [ "$(grep -c 2612 "$K/mv_file_format.cpp")" = 3 ] || { echo "reader edit did not apply"; exit 1; }
fi
cd "$SRC/starter" && ./build_script.sh -arch=linux64_gf -nt=2 -open_reader > build.log 2>&1 || true
gcc -O2 -c "$HERE/stubs.c" -o "$SRC/starter/stubs.o"
cd "$SRC/starter/cbuild_starter_linux64_gf"
bash -c "$(cat CMakeFiles/starter_linux64_gf.dir/link.txt) $SRC/starter/stubs.o"
cp starter_linux64_gf "$SRC/exec/"
cd "$SRC/engine" && ./build_script.sh -arch=linux64_gf -nt=2 > build.log 2>&1
ls "$SRC/exec"
