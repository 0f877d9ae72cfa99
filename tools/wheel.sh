#!/usr/bin/env bash
# The product wheel (make wheel): tools/wheel.sh [BUILD [DIST]] writes DIST/stridefix-<version>-*.whl
# (default build/ and dist/) with stridefix_common (and board.dbc), stridefix_sim, stridefix_analyzer,
# and from the CMake build BUILD the LCM Python types and, when built, the native solver (setup.py says
# what and why). The lab is not in it (lab/pyproject.toml).
# The sources are staged into a fresh folder first: setuptools writes its build/ and *.egg-info into
# the folder it builds, and a build/lib kept from an earlier wheel would carry deleted modules along.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=$(realpath "${1:-build}")
DIST=$(realpath -m "${2:-dist}")
PY=${PY:-.venv/bin/python}
if [ ! -d "$BUILD/lcmtypes/python/stridefix" ]; then
  echo "wheel: $BUILD has no generated LCM types: run make build first" >&2
  exit 1
fi
stage=$(mktemp -d "${TMPDIR:-/tmp}/stridefix-wheel.XXXXXX")
trap 'rm -rf "$stage"' EXIT
cp pyproject.toml setup.py VERSION "$stage/"
for pkg in common/stridefix_common hil-sim/stridefix_sim analyzer/stridefix_analyzer; do
  mkdir -p "$stage/$(dirname "$pkg")"
  # -L: board.dbc is a link to firmware/board.dbc; the wheel gets the file
  cp -RL "$pkg" "$stage/$pkg"
done
find "$stage" -name __pycache__ -prune -exec rm -rf {} +
mkdir -p "$DIST"
STRIDEFIX_BUILD=$BUILD "$PY" -m pip wheel -q --disable-pip-version-check --no-deps --no-build-isolation \
  "$stage" -w "$DIST"
ls "$DIST"/stridefix-"$(cat VERSION)"-*.whl
