#!/usr/bin/env bash
# Installs every dependency (Debian 12 packages) and builds seam into ./build.
# Usage: bash scripts/setup.sh [extra cmake -D options]
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libsimdjson-dev libcli11-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libglpk-dev libgmp-dev libtbb-dev
  libginac-dev libcln-dev libboost-dev
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev libocct-data-exchange-dev
  libocct-ocaf-dev   # XDE documents (names, colours, layers of STEP/IGES kept by convert and heal)
  python3-jsonschema
  pybind11-dev python3-dev python3-numpy python3-pytest python3-distributed   # the Python module (python/)
  nodejs chromium chromium-driver   # the report's 3-D view (web/: three.js bundled at build time) and its browser test
)
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The report's 3-D view (docs/report.md): three.js, esbuild and playwright-core pinned in web/package-lock.json,
# installed before the build so that the report bundles the view and the browser test is registered. Debian's nodejs
# comes without npm (a NodeSource nodejs has it built in).
if ! command -v npm >/dev/null; then
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends npm
fi
(cd web && npm ci --no-audit --no-fund)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSEAM_WITH_OCCT=ON "$@"
cmake --build build -j "$(nproc)"

# The Python module `seam` (README "Python"): build/python/seam, built for Debian's /usr/bin/python3 (its
# python3-numpy, python3-pytest, python3-distributed). A seam.pth file puts build/python on that Python's path; when
# another python3 of the same version comes first on PATH (pyenv, a venv), it gets a seam.pth too, which also
# appends Debian's dist-packages (NumPy, Dask) after its own packages, so that `python3 -c "import seam"` works.
if [ -d build/python/seam ]; then
  pth_line="$(pwd)/build/python"
  for py in /usr/bin/python3 "$(command -v python3 || true)"; do
    [ -x "$py" ] || continue
    site="$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])' 2>/dev/null)" || continue
    lines="$pth_line"
    if [ "$py" != /usr/bin/python3 ]; then
      version="$("$py" -c 'import sys; print(sys.version_info[:2])' 2>/dev/null)" || continue
      if [ "$version" != "$(/usr/bin/python3 -c 'import sys; print(sys.version_info[:2])')" ]; then
        echo "setup: $py is not the version of /usr/bin/python3: use /usr/bin/python3 for the module seam"
        continue
      fi
      lines="$pth_line"$'\n'"/usr/lib/python3/dist-packages"
    fi
    $SUDO mkdir -p "$site" && printf '%s\n' "$lines" | $SUDO tee "$site/seam.pth" >/dev/null
    echo "setup: $site/seam.pth -> $pth_line"
  done
fi
