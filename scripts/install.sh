#!/usr/bin/env bash
# Install what drumflow needs on Debian 12 (bookworm), then the package into .venv.
# Idempotent: what is already there is not installed again. Run from anywhere.
#
#   bash scripts/install.sh                      # Debian's LIGGGHTS (the default, what CI runs)
#   bash scripts/install.sh --liggghts-native    # also LIGGGHTS 3.8 built from its upstream source
#                                                # with -O3 -march=native into $LIGGGHTS_PREFIX
#                                                # (default /opt/drumflow/liggghts-native; ~10 min
#                                                # on 2 cores); use it with
#                                                # export DRUMFLOW_LIGGGHTS_PREFIX=that prefix
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"

native=0
for arg in "$@"; do
  case "$arg" in
    --liggghts-native) native=1 ;;
    *) echo "drumflow install: unknown option $arg (known: --liggghts-native)" >&2; exit 2 ;;
  esac
done

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

# Solvers and the libraries the gmsh and VTK wheels load (GLU, X fonts, off-screen GL).
apt_packages=(liggghts openmpi-bin openfoam python3-venv python3-pip
              libglu1-mesa libxcursor1 libxft2 libxinerama1 libxrender1 libgl1 libegl1 libosmesa6
              chromium
              slurmctld slurmd munge slurm-client)  # SLURM: `drumflow sweep` on a cluster, its tests
missing=()
for p in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "drumflow install: apt packages: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

PY="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
# Reinstall only when pyproject.toml changed since the last install.
stamp=".venv/.drumflow-installed"
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ] || ! .venv/bin/python -c "import drumflow" 2>/dev/null \
   || [ ! -x .venv/bin/mkdocs ]; then
  .venv/bin/python -m pip install -q --upgrade pip >/dev/null
  # test: the test suite's tools; docs: the documentation site that scripts/test.sh builds.
  .venv/bin/python -m pip install -q -e ".[test,docs]"
  touch "$stamp"
fi
if [ "$native" -eq 1 ]; then
  # The upstream tarball from Debian's source package (deb-src derived from the apt sources; the
  # Debian patch tarball is not needed: scripts/build_liggghts.sh fixes the build for GCC 12).
  prefix="${LIGGGHTS_PREFIX:-/opt/drumflow/liggghts-native}"
  src_root="${LIGGGHTS_SOURCE_DIR:-/var/tmp/drumflow-liggghts-src}"
  build_packages=(cmake make g++ libopenmpi-dev libjpeg-dev dpkg-dev)
  need=()
  for p in "${build_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
  done
  if [ ! -f /etc/apt/sources.list.d/drumflow-src.sources ] && ! grep -rqs "^Types: deb-src\|^deb-src" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    uri=$(grep -rhs -m1 "^URIs:" /etc/apt/sources.list.d/debian.sources | awk '{print $2}')
    printf 'Types: deb-src\nURIs: %s\nSuites: bookworm bookworm-updates\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
      "${uri:-http://deb.debian.org/debian}" | $SUDO tee /etc/apt/sources.list.d/drumflow-src.sources >/dev/null
  fi
  $SUDO apt-get update -qq
  if [ "${#need[@]}" -gt 0 ]; then
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
  fi
  mkdir -p "$src_root"
  if [ ! -d "$src_root/LIGGGHTS-PUBLIC-3.8.0" ]; then
    # The .debian.tar.xz of the source package is missing from the mirror: only the .orig tarball.
    (cd "$src_root" && { apt-get source --download-only liggghts >/dev/null 2>&1 || true; } \
       && tarball=$(ls liggghts_*.orig.tar.xz 2>/dev/null | head -1) \
       && [ -n "$tarball" ] && tar xf "$tarball") \
      || { echo "drumflow install: could not fetch the LIGGGHTS source (apt-get source liggghts)" >&2; exit 1; }
  fi
  bash scripts/build_liggghts.sh "$src_root/LIGGGHTS-PUBLIC-3.8.0" "$prefix" "$src_root/build-native"
  echo "drumflow install: LIGGGHTS built from source in $prefix; use it with"
  echo "  export DRUMFLOW_LIGGGHTS_PREFIX=$prefix"
fi

# `liggghts -h` exits non-zero; only its version line matters here.
version=$( { liggghts -h 2>/dev/null || true; } | grep -m1 -o 'LIGGGHTS-PUBLIC [0-9.]*' || true)
.venv/bin/drumflow --help >/dev/null
echo "drumflow install: ok (${version:-LIGGGHTS installed}; drumflow CLI in .venv/bin)"
