#!/usr/bin/env bash
# Builds ETH3D's multi-view evaluation tool (tests/third_party/eth3d_multi_view_evaluation, the
# reference of `sfmeval eth3d`) once into .tools/eth3d/: ETH3DMultiViewEvaluation (the tool as
# upstream builds it) and ETH3DMultiViewEvaluation9 (the same sources, printing 9 significant
# digits: sfmeval_build/print_precision.cc). Idempotent (a stamp of the sources and flags).
#
# From Debian 12 packages only. libpcl-dev depends on all of PCL, VTK's and Qt's -dev packages and
# OpenMPI (305 packages); the tool needs PCL's common, io, kdtree and search libraries and
# their headers. So the runtime libraries come from requirements/apt-eth3d.txt (installed by
# scripts/setup.sh, with Eigen, Boost.Filesystem, LZ4 and cmake), and the headers of libpcl-dev
# and libflann-dev are unpacked from their .debs (apt-get download + dpkg -x, 25 MB) into
# .tools/eth3d/sysroot without installing their dependency trees.
set -euo pipefail
cd "$(dirname "$0")/.."
src=tests/third_party/eth3d_multi_view_evaluation
out=.tools/eth3d
flags=(-std=c++17 -O2 -DNDEBUG -msse2 -msse3 -fopenmp)
stamp=$( (cat "$src"/src/* "$src"/sfmeval_build/*; echo "${flags[*]}") | sha256sum | cut -d' ' -f1)
if [ -x "$out/ETH3DMultiViewEvaluation" ] && [ -x "$out/ETH3DMultiViewEvaluation9" ] &&
  [ "$(cat "$out/stamp" 2>/dev/null)" = "$stamp" ]; then
  exit 0
fi
t0=$SECONDS
mkdir -p "$out/obj"
sysroot=$out/sysroot
if [ ! -d "$sysroot/usr/include/pcl-1.13" ] || [ ! -d "$sysroot/usr/include/flann" ]; then
  debs=$(mktemp -d)
  (cd "$debs" && apt-get download libpcl-dev libflann-dev >/dev/null 2>&1) || {
    echo "build-eth3d-tool: apt-get download libpcl-dev libflann-dev failed" >&2; exit 1; }
  rm -rf "$sysroot"
  for d in "$debs"/*.deb; do dpkg -x "$d" "$sysroot"; done
  rm -rf "$debs"
fi
inc=(-I"$src/src" -I"$sysroot/usr/include/pcl-1.13" -I"$sysroot/usr/include" -I/usr/include/eigen3)
lib=/usr/lib/x86_64-linux-gnu
for f in accuracy completeness meshlab_project; do
  g++ "${flags[@]}" "${inc[@]}" -c "$src/src/$f.cc" -o "$out/obj/$f.o"
done
g++ "${flags[@]}" "${inc[@]}" -c "$src/src/tinyxml2.cpp" -o "$out/obj/tinyxml2.o"
g++ "${flags[@]}" "${inc[@]}" -c "$src/src/main.cc" -o "$out/obj/main.o"
g++ "${flags[@]}" "${inc[@]}" -Dmain=eth3d_main -c "$src/src/main.cc" -o "$out/obj/main9.o"
g++ "${flags[@]}" -c "$src/sfmeval_build/print_precision.cc" -o "$out/obj/print_precision.o"
libs=("$lib/libpcl_io.so.1.13" "$lib/libpcl_io_ply.so.1.13" "$lib/libpcl_search.so.1.13"
  "$lib/libpcl_kdtree.so.1.13" "$lib/libpcl_common.so.1.13" "$lib/libflann_cpp.so.1.9"
  -lboost_filesystem -llz4 -fopenmp)
common=("$out/obj/accuracy.o" "$out/obj/completeness.o" "$out/obj/meshlab_project.o" "$out/obj/tinyxml2.o")
g++ -o "$out/ETH3DMultiViewEvaluation" "$out/obj/main.o" "${common[@]}" "${libs[@]}"
g++ -o "$out/ETH3DMultiViewEvaluation9" "$out/obj/main9.o" "$out/obj/print_precision.o" "${common[@]}" "${libs[@]}"
echo "$stamp" >"$out/stamp"
echo "build-eth3d-tool: built $out/ETH3DMultiViewEvaluation{,9} in $((SECONDS - t0)) s"
