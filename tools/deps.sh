#!/usr/bin/env bash
# Installs what StrideFix needs and is missing; safe to run again (make deps).
#  1. Debian packages (apt-get update first, only when something is missing).
#  2. A project virtualenv in .venv with the pinned requirements.txt, StrideFix itself and the lab
#     (lab/pyproject.toml: `stridefix-lab`, not in the product wheel), both editable, re-installed only
#     when requirements.txt or a pyproject.toml changed.
#  3. A .pth file so the venv imports what the build generates (development; the product wheel of
#     `make wheel` carries them, and so does `cmake --install`, docs/deployment.md "Install on a logger"): the LCM
#     Python bindings and the native solver module (stridefix_native, with its scipy reference beside it).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
BUILD=${BUILD:-build}
# clang and cppcheck: the quality gates (make check-clang, make check-static); libclang-rt-14-dev:
# the libFuzzer runtime (make check-fuzz, make fuzz).
DEBS=(liblcm-dev liblcm-bin libeigen3-dev libceres-dev libcmocka-dev libinih-dev python3-dev cmake g++ gcc make pkg-config
      clang cppcheck libclang-rt-14-dev)
# make check-arm: Debian's armhf cross toolchain (its C library, libc6-dev-armhf-cross, is only a
# recommends of the cross gcc, so it is named), qemu's user-mode emulator and cmocka built for armhf,
# a multiarch package: it needs the armhf architecture in dpkg (added below), the cross gcc does not.
DEBS+=(crossbuild-essential-armhf libc6-dev-armhf-cross qemu-user libcmocka-dev:armhf)
# valgrind: callgrind counts the core's instructions (bench perf, bench particle-cost and their tests).
DEBS+=(valgrind)
# chromium: `stridefix live`'s page is tested in headless Chromium (playwright drives Debian's browser;
# no browser download).
DEBS+=(chromium)
# can-utils: log2asc and asc2log, candump and canplayer (tests/python/can: the Vector ASC round trip,
# whose asc2log writes the direction flags the candump parser reads; docs/deployment.md "CAN tools").
DEBS+=(can-utils)
# lcm-spy and the Java types (lcmtypes/CMakeLists.txt builds build/lcmtypes/java/stridefix_lcmtypes.jar
# when a JDK and lcm.jar are found; `stridefix spy` / make spy start lcm.spy.Spy from lcm.jar):
# liblcm-java (lcm.jar: the LCM Java library, lcm-spy's classes), libjchart2d-java (lcm-spy's field
# plots: its message view fails without it), openjdk-17-jdk-headless (javac and jar; lcm-spy's window
# needs a display and the full JRE, openjdk-17-jre, which the headless JDK does not pull in).
DEBS+=(liblcm-java libjchart2d-java openjdk-17-jdk-headless)
# xvfb, xauth, x11-utils (xwininfo) and the full JRE (AWT's X11 toolkit): test_spy opens lcm-spy's
# window on a virtual display (Xvfb: no screen, no network) and finds it by its title.
DEBS+=(xvfb xauth x11-utils openjdk-17-jre)
# help2man: stridefixd.1 from --help (cmake/install.cmake); man-db and groff-base render it
# (tests/python/packaging/test_install.py).
DEBS+=(help2man man-db groff-base)

missing=()
for p in "${DEBS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ! python3 -c 'import venv, ensurepip' 2>/dev/null; then missing+=(python3-venv); fi
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "deps: installing Debian packages: ${missing[*]}"
  if [[ " ${missing[*]} " == *":armhf "* ]] && ! dpkg --print-foreign-architectures | grep -qx armhf; then
    echo "deps: adding the armhf architecture to dpkg (for libcmocka-dev:armhf)"
    $SUDO dpkg --add-architecture armhf
  fi
  $SUDO apt-get update -qq
  # --no-remove: an armhf package must never take a host package away (apt stops with an error instead).
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends --no-remove "${missing[@]}"
fi

if [ ! -x "$VENV/bin/python" ]; then
  echo "deps: creating virtualenv $VENV"
  python3 -m venv "$VENV"
fi
stamp="$VENV/.stridefix-deps"
want=$(cat requirements.txt pyproject.toml lab/pyproject.toml VERSION | sha256sum | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "deps: installing Python packages into $VENV"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r requirements.txt
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e .
  # after the product: a venv whose product install still held stridefix-lab gives the script up first
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e lab
  echo "$want" > "$stamp"
fi
site=$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
printf '%s\n' "$(pwd)/$BUILD/lcmtypes/python" "$(pwd)/$BUILD/analyzer/native" > "$site/stridefix_lcmtypes.pth"
