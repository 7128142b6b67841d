#!/usr/bin/env bash
# build_liggghts.sh -- LIGGGHTS-PUBLIC 3.8.0 from upstream source, tuned for THIS machine
# (-O3 -march=native), as an optional faster solver for drumflow.
#
# Usage:  build_liggghts_native.sh SRC_DIR PREFIX [BUILD_DIR]
#   SRC_DIR    the extracted LIGGGHTS-PUBLIC-3.8.0 tree (the one holding src/CMakeLists.txt)
#   PREFIX     install prefix, e.g. /opt/drumflow/liggghts-native; gets
#                bin/liggghts, lib/libliggghts.so.3.8.0 (+ libliggghts.so.3, libliggghts.so links),
#                include/library.h, build-flags.txt
#   BUILD_DIR  out-of-source build directory (default: SRC_DIR/../build-native)
#
# Environment knobs (defaults in brackets):
#   JOBS [2]      make -j
#   NICE [19]     every compile step runs under `nice -n $NICE`
#   LIGGGHTS_CXXFLAGS ["-O3 -march=native -funroll-loops -fstrict-aliasing -std=c++11 -fPIC -Wno-literal-suffix"]
#   RUN_CHECK [1] run a 300-step smoke deck (needs mpirun) after installing
#   ONLY_FIXES [0] 1: apply the source fixes and stop
#
# Use with drumflow:
#   export DRUMFLOW_LIGGGHTS_PREFIX=PREFIX (drumflow then launches PREFIX/bin/liggghts, its coupling
#   loop loads PREFIX/lib/libliggghts.so.3, and every manifest records PREFIX/build-flags.txt).
#   `bash scripts/install.sh --liggghts-native` fetches the source and runs this script.
#
# What it does (idempotent: re-running re-applies nothing already applied, rebuilds only what is
# out of date, reinstalls over the previous install):
#   1. checks the tools (cmake, make, mpicc/mpicxx of OpenMPI with its headers: Debian package
#      libopenmpi-dev; libjpeg headers are optional: libjpeg-dev);
#   2. source fixes, each applied only if not yet applied:
#      a. src/utils.h: Utils::int_to_string static_casts the rvalue `std::ostringstream() << ...`
#         to `std::ostringstream&`; GCC >= 11 (libstdc++ rvalue operator<< returns the derived
#         stream as an rvalue) rejects that -> a named local stream;
#      b. src/CMakeLists.txt: the shared library gets VERSION 3.8.0 / SOVERSION 3, i.e. the file
#         libliggghts.so.3.8.0 with SONAME libliggghts.so.3, as Debian's libliggghts3;
#      c. src/dump_mesh_vtk.{h,cpp}: missing LAMMPS_VTK guard (needed to build without VTK);
#      d. src/finish.cpp: ordered comparison of a pointer with 0 (an error in GCC >= 11);
#   3. configures with CMake (C/C++ compilers mpicc/mpicxx, no build type so that only the flags
#      above are used, VTK disabled: drumflow uses no VTK dump style, and Debian 12's VTK 9 is
#      not usable by this CMakeLists (VTK_USE_FILE is gone in VTK 9));
#   4. builds (nice'd), installs, writes PREFIX/build-flags.txt, checks the result.
set -Eeuo pipefail

me=build_liggghts
die() { echo "$me: ERROR: $*" >&2; exit 1; }
log() { echo "$me: $*"; }
trap 'echo "$me: FAILED (line $LINENO: $BASH_COMMAND)" >&2' ERR

[ $# -ge 2 ] && [ $# -le 3 ] || die "usage: $0 SRC_DIR PREFIX [BUILD_DIR]"
[ -d "$1" ] || die "source dir $1 does not exist"
SRC=$(cd "$1" && pwd)
SRCDIR=$SRC/src
[ -f "$SRCDIR/CMakeLists.txt" ] || die "$SRCDIR/CMakeLists.txt not found: not a LIGGGHTS-PUBLIC tree"
mkdir -p "$2" || die "cannot create prefix $2"
PREFIX=$(cd "$2" && pwd)
BUILD=${3:-$(dirname "$SRC")/build-native}
mkdir -p "$BUILD"
BUILD=$(cd "$BUILD" && pwd)
[ "$BUILD" != "$SRCDIR" ] || die "BUILD_DIR must not be the source dir"

JOBS=${JOBS:-2}
NICE=${NICE:-19}
RUN_CHECK=${RUN_CHECK:-1}
FLAGS=${LIGGGHTS_CXXFLAGS:-"-O3 -march=native -funroll-loops -fstrict-aliasing -std=c++11 -fPIC -Wno-literal-suffix"}

version=$(cat "$SRCDIR/version_liggghts.txt" 2>/dev/null || true)
[ "$version" = "3.8.0" ] || die "expected LIGGGHTS 3.8.0 sources, src/version_liggghts.txt says '$version'"

# ---------------------------------------------------------------- 1. tools
for t in cmake make mpicc mpicxx readelf nm; do
  command -v "$t" >/dev/null || die "$t not found (apt-get install cmake make openmpi-bin libopenmpi-dev binutils)"
done
mpiver=$(mpicxx --showme:version 2>&1) || die "mpicxx --showme:version failed"
grep -qi "open mpi" <<<"$mpiver" || die "mpicxx is not Open MPI's (Debian's liggghts uses Open MPI)"
printf '#include <mpi.h>\nint main(int c,char**v){MPI_Init(&c,&v);MPI_Finalize();return 0;}\n' > "$BUILD/mpitest.cpp"
nice -n "$NICE" mpicxx "$BUILD/mpitest.cpp" -o "$BUILD/mpitest" 2>"$BUILD/mpitest.err" \
  || die "mpicxx cannot compile+link an MPI program (missing libopenmpi-dev?): $(head -3 "$BUILD/mpitest.err")"
rm -f "$BUILD/mpitest" "$BUILD/mpitest.cpp" "$BUILD/mpitest.err"
[ -f /usr/include/jpeglib.h ] || log "warning: no jpeglib.h (libjpeg-dev): building without dump image/movie JPEG"

# ---------------------------------------------------------------- 2. source fixes
# Each fix: keep a pristine copy FILE.orig once, then apply the fix only if its marker is absent.
keep_orig() { [ -f "$1.orig" ] || cp -p "$1" "$1.orig"; }

# 2a. utils.h: GCC >= 11 rejects static_cast<std::ostringstream&>(std::ostringstream() << ...)
f=$SRCDIR/utils.h
if ! grep -q 'drumflow: GCC >= 11 fix' "$f"; then
  keep_orig "$f"
  grep -q 'return static_cast< std::ostringstream & >(( std::ostringstream() << std::dec << a ) ).str();' "$f" \
    || die "fix 2a: pattern not found in $f"
  sed -i 's|^    return static_cast< std::ostringstream & >(( std::ostringstream() << std::dec << a ) ).str();$|    std::ostringstream oss; oss << std::dec << a; return oss.str(); /* drumflow: GCC >= 11 fix */|' "$f"
  grep -q 'drumflow: GCC >= 11 fix' "$f" || die "fix 2a failed on $f"
  log "applied fix 2a (utils.h int_to_string)"
fi

# 2b. CMakeLists.txt: versioned shared library, SONAME libliggghts.so.3 (as Debian's).
f=$SRCDIR/CMakeLists.txt
if ! grep -q 'OUTPUT_NAME liggghts VERSION 3.8.0 SOVERSION 3' "$f"; then
  keep_orig "$f"
  grep -q '^SET_TARGET_PROPERTIES(liggghts_shared PROPERTIES OUTPUT_NAME liggghts)$' "$f" \
    || die "fix 2b: pattern not found in $f"
  sed -i 's/^SET_TARGET_PROPERTIES(liggghts_shared PROPERTIES OUTPUT_NAME liggghts)$/SET_TARGET_PROPERTIES(liggghts_shared PROPERTIES OUTPUT_NAME liggghts VERSION 3.8.0 SOVERSION 3)/' "$f"
  grep -q 'OUTPUT_NAME liggghts VERSION 3.8.0 SOVERSION 3' "$f" || die "fix 2b failed on $f"
  log "applied fix 2b (CMakeLists.txt SOVERSION 3)"
fi

# 2c. dump_mesh_vtk.{h,cpp} (dump mesh/vtk, mesh/gran/VTK) lack the LAMMPS_VTK guard every other
#     VTK dump style has: without VTK the .cpp cannot find vtkDataSet.h and the style header
#     (style_dump.h, included by lammps.cpp, output.cpp, write_dump.cpp) names the undefined
#     DumpVTK. Guard both whole files.
for f in "$SRCDIR/dump_mesh_vtk.h" "$SRCDIR/dump_mesh_vtk.cpp"; do
  if ! grep -q 'drumflow: VTK guard' "$f"; then
    keep_orig "$f"
    sed -i '1i #if defined(LAMMPS_VTK) /* drumflow: VTK guard, as the other VTK dump styles */' "$f"
    echo '#endif /* LAMMPS_VTK (drumflow: VTK guard) */' >> "$f"
    log "applied fix 2c ($(basename "$f") LAMMPS_VTK guard)"
  fi
done

# 2d. finish.cpp: `numneigh > 0` compares a pointer (int*) with 0; GCC >= 11 makes the ordered
#     comparison an error. What is meant is "the list has a numneigh array" (as LAMMPS fixed it).
f=$SRCDIR/finish.cpp
if ! grep -q 'drumflow: was "> 0", a pointer' "$f"; then
  keep_orig "$f"
  grep -q '^      if (neighbor->lists\[m\]->numneigh > 0) {$' "$f" || die "fix 2d: pattern not found in $f"
  sed -i 's|^      if (neighbor->lists\[m\]->numneigh > 0) {$|      if (neighbor->lists[m]->numneigh != NULL) { /* drumflow: was "> 0", a pointer */|' "$f"
  grep -q 'drumflow: was "> 0", a pointer' "$f" || die "fix 2d failed on $f"
  log "applied fix 2d (finish.cpp pointer comparison)"
fi

if [ "${ONLY_FIXES:-0}" = 1 ]; then log "ONLY_FIXES=1: source fixes applied, stopping"; exit 0; fi

# ---------------------------------------------------------------- 3. configure
log "configuring in $BUILD with CXXFLAGS: $FLAGS"
nice -n "$NICE" cmake -S "$SRCDIR" -B "$BUILD" \
  -DCMAKE_C_COMPILER="$(command -v mpicc)" -DCMAKE_CXX_COMPILER="$(command -v mpicxx)" \
  -DCMAKE_BUILD_TYPE= \
  -DCMAKE_CXX_FLAGS="$FLAGS" \
  -DCMAKE_DISABLE_FIND_PACKAGE_VTK=ON \
  > "$BUILD/configure.log" 2>&1 || { tail -30 "$BUILD/configure.log" >&2; die "cmake configure failed ($BUILD/configure.log)"; }
grep -q '^CXX_FLAGS = .*-march=native' "$BUILD/CMakeFiles/liggghts_obj.dir/flags.make" \
  || die "configured flags do not contain -march=native (see $BUILD/CMakeFiles/liggghts_obj.dir/flags.make)"

# ---------------------------------------------------------------- 4. build
log "building (nice -n $NICE make -j$JOBS), log: $BUILD/build.log"
t0=$(date +%s)
nice -n "$NICE" make -C "$BUILD" -j"$JOBS" liggghts_shared liggghts_bin > "$BUILD/build.log" 2>&1 \
  || { grep -n -A3 'error' "$BUILD/build.log" | head -40 >&2; die "build failed ($BUILD/build.log)"; }
t1=$(date +%s)
log "build step took $((t1 - t0)) s"

LIB=$BUILD/libliggghts.so.3.8.0
BIN=$BUILD/liggghts
[ -f "$LIB" ] || die "$LIB not built"
[ -x "$BIN" ] || die "$BIN not built"
soname=$(readelf -d "$LIB" | sed -n 's/.*Library soname: \[\(.*\)\].*/\1/p')
[ "$soname" = "libliggghts.so.3" ] || die "SONAME of $LIB is '$soname', expected libliggghts.so.3"

# ---------------------------------------------------------------- 5. install
log "installing into $PREFIX"
mkdir -p "$PREFIX/bin" "$PREFIX/lib" "$PREFIX/include"
install -m 0755 "$BIN" "$PREFIX/bin/liggghts"
install -m 0755 "$LIB" "$PREFIX/lib/libliggghts.so.3.8.0"
ln -sfn libliggghts.so.3.8.0 "$PREFIX/lib/libliggghts.so.3"
ln -sfn libliggghts.so.3 "$PREFIX/lib/libliggghts.so"
install -m 0644 "$SRCDIR/library.h" "$PREFIX/include/library.h"

{
  echo "# LIGGGHTS-PUBLIC $version built by $0 on $(date -u +%Y-%m-%dT%H:%M:%SZ) on $(uname -n)"
  echo "source:        $SRC"
  echo "build dir:     $BUILD"
  echo "CMAKE_CXX_FLAGS (as given): $FLAGS"
  echo "compile flags (flags.make):"
  sed -n 's/^\(CXX_FLAGS\|CXX_DEFINES\|CXX_INCLUDES\) = /  \1 = /p' "$BUILD/CMakeFiles/liggghts_obj.dir/flags.make"
  echo "-march=native resolves to: $(gcc -march=native -Q --help=target 2>/dev/null | awk '$1=="-march="{print $2}')"
  echo "  (the result needs this CPU's instruction set; rebuild on another machine)"
  echo "C++ compiler:  $(mpicxx --showme:command 2>/dev/null || echo mpicxx) via mpicxx: $(mpicxx --version | sed -n 1p)"
  echo "mpicxx wraps:  $(mpicxx --showme)"
  echo "MPI:           $(mpicxx --showme:version 2>&1)"
  echo "cmake:         $(cmake --version | sed -n 1p)"
  echo "VTK:           disabled (-DCMAKE_DISABLE_FIND_PACKAGE_VTK=ON)"
  echo "JPEG:          $(grep -q 'LAMMPS_JPEG' "$BUILD/CMakeFiles/liggghts_obj.dir/flags.make" && echo enabled || echo disabled)"
  echo "source fixes:  $(cd "$SRCDIR" && ls *.orig 2>/dev/null | sed 's/\.orig$//' | tr '\n' ' ')"
  echo "build step:    $((t1 - t0)) s for this run of the script (nice -n $NICE make -j$JOBS; an up-to-date tree rebuilds only universe.cpp, whose version string has the build date)"
} > "$PREFIX/build-flags.txt"

# ---------------------------------------------------------------- 6. checks
ldd_out=$(ldd "$PREFIX/lib/libliggghts.so.3") || die "ldd failed on the library"
if grep -q 'not found' <<<"$ldd_out"; then die "unresolved libraries: $(grep 'not found' <<<"$ldd_out")"; fi
syms=$(nm -D --defined-only "$PREFIX/lib/libliggghts.so.3") || die "nm failed on the library"
for sym in lammps_open_no_mpi lammps_command lammps_file lammps_extract_atom lammps_extract_fix \
           lammps_extract_global lammps_close; do
  grep -qw "$sym" <<<"$syms" || die "library lacks $sym"
done
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1} OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
help=$("$PREFIX/bin/liggghts" -h 2>&1 || true)   # -h exits 1 by design
grep -q "LIGGGHTS-PUBLIC 3.8.0" <<<"$help" || die "bin/liggghts -h does not print its version"
# The styles drumflow's decks use (drumflow/dem/templates/*.j2, drumflow/verify):
for style in granular gran hertz history cdt property/global gravity mesh/surface wall/gran \
             move/mesh heat/gran/conduction property/atom addforce nve/sphere freeze setforce \
             particletemplate/sphere particledistribution/discrete insert/pack reduce erotate/sphere \
             pair/gran/local custom mesh/stl; do
  grep -qE "(^| )$style( |$)" <<<"$help" || die "bin/liggghts lacks style $style"
done
python3 - "$PREFIX/lib/libliggghts.so.3" <<'EOF' || die "ctypes cannot load the library with RTLD_GLOBAL"
import ctypes, sys
lib = ctypes.CDLL(sys.argv[1], mode=ctypes.RTLD_GLOBAL)
lib.lammps_open_no_mpi, lib.lammps_close
EOF

if [ "$RUN_CHECK" = 1 ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  cat > "$work/floor.stl" <<'EOF'
solid floor
facet normal 0 0 1
outer loop
vertex -0.05 -0.05 0
vertex 0.05 -0.05 0
vertex 0.05 0.05 0
endloop
endfacet
facet normal 0 0 1
outer loop
vertex -0.05 -0.05 0
vertex 0.05 0.05 0
vertex -0.05 0.05 0
endloop
endfacet
endsolid floor
EOF
  cat > "$work/in.check" <<'EOF'
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.05 0.05 -0.05 0.05 -0.001 0.1 units box
create_box 2 box
neighbor 0.001 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.6 0.5 0.5 0.5
fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.4 0.4 0.4
fix m5 all property/global coefficientRollingFriction peratomtypepair 2 0.1 0.1 0.1 0.1
fix m6 all property/global thermalConductivity peratomtype 1.0 1.0
fix m7 all property/global thermalCapacity peratomtype 800. 800.
pair_style gran model hertz tangential history rolling_friction cdt
pair_coeff * *
timestep 5e-5
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix floor all mesh/surface file floor.stl type 2
fix walls all wall/gran model hertz tangential history rolling_friction cdt mesh n_meshes 1 meshes floor
fix heat all heat/gran/conduction initial_temperature 300.
fix integrate all nve/sphere
region ins block -0.04 0.04 -0.04 0.04 0.002 0.05 units box
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.003
fix pdd1 all particledistribution/discrete 15485867 1 pts1 1.0
fix ins all insert/pack seed 32452843 distributiontemplate pdd1 vel constant 0. 0. -0.5 insert_every once overlapcheck yes all_in yes particles_in_region 200 region ins
thermo_style custom step atoms ke
thermo 100
run 300
EOF
  ( cd "$work" && mpirun -np 1 "$PREFIX/bin/liggghts" -in in.check -log log.check > out.check 2>&1 ) \
    || { tail -20 "$work/out.check" >&2; die "smoke deck failed"; }
  grep -qE '^ +300 +200 ' "$work/log.check" || { tail -20 "$work/out.check" >&2; die "smoke deck did not reach step 300 with 200 atoms"; }
  log "smoke deck OK: $(grep -E '^ +300 +200 ' "$work/log.check")"
fi

log "done: $PREFIX/bin/liggghts, $PREFIX/lib/libliggghts.so.3 (flags in $PREFIX/build-flags.txt)"
