#!/usr/bin/env bash
# Install what drumflow needs on Debian 12 (bookworm), then the package into .venv.
# Idempotent: what is already there is not installed again. Run from anywhere.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"

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
# `liggghts -h` exits non-zero; only its version line matters here.
version=$( { liggghts -h 2>/dev/null || true; } | grep -m1 -o 'LIGGGHTS-PUBLIC [0-9.]*' || true)
.venv/bin/drumflow --help >/dev/null
echo "drumflow install: ok (${version:-LIGGGHTS installed}; drumflow CLI in .venv/bin)"
