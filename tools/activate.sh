# SPDX-License-Identifier: Apache-2.0
# Source this file (bash) to get a shell in which the wirefish executables work:
#   source tools/activate.sh
# It activates the project's virtual environment and the colcon workspace (install/setup.bash).
# On a full ROS 2 Jazzy install, source /opt/ros/jazzy/setup.bash first.

_wf_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
_wf_venv="${WIREFISH_VENV:-$_wf_root/.venv}"

if [ ! -x "$_wf_venv/bin/python" ] || [ ! -f "$_wf_root/install/setup.bash" ]; then
  echo "wirefish: not set up yet: run 'make setup' in $_wf_root first" >&2
  return 1 2>/dev/null || exit 1
fi

# shellcheck disable=SC1091
source "$_wf_venv/bin/activate"
if [ -f "$_wf_venv/.wirefish-wheels" ]; then
  # ROS 2 from PyPI wheels: the venv prefix is the underlay (ament index, CMake configs).
  case ":${AMENT_PREFIX_PATH:-}:" in
    *":$_wf_venv:"*) ;;
    *) export AMENT_PREFIX_PATH="$_wf_venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}" ;;
  esac
  case ":${CMAKE_PREFIX_PATH:-}:" in
    *":$_wf_venv:"*) ;;
    *) export CMAKE_PREFIX_PATH="$_wf_venv${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}" ;;
  esac
fi
# colcon's setup scripts read unset variables; relax nounset while sourcing them.
case $- in *u*) _wf_nounset=1; set +u ;; *) _wf_nounset= ;; esac
# shellcheck disable=SC1091
source "$_wf_root/install/setup.bash"
[ -n "$_wf_nounset" ] && set -u
# The `wirefish` command (installed the ament way, under lib/wirefish_cli) on PATH.
case ":$PATH:" in
  *":$_wf_root/install/wirefish_cli/lib/wirefish_cli:"*) ;;
  *) export PATH="$_wf_root/install/wirefish_cli/lib/wirefish_cli:$PATH" ;;
esac
_wf_config="$_wf_root/install/wirefish_bringup/share/wirefish_bringup/config"
# LOCALHOST brings rmw_fastrtps' shared memory back whatever the transports say: one host is
# served by the loopback profile instead (UDPv4 on 127.0.0.1 only) under the range rmw leaves
# alone (wirefish_bringup.dds_profile). A profile already set is kept, and LOCALHOST with it.
if [ -z "${FASTRTPS_DEFAULT_PROFILES_FILE+x}" ] && [ "${ROS_AUTOMATIC_DISCOVERY_RANGE-}" = LOCALHOST ] \
    && [ -z "${ROS_STATIC_PEERS-}" ]; then
  export FASTRTPS_DEFAULT_PROFILES_FILE="$_wf_config/fastdds_loopback.xml"
  export ROS_AUTOMATIC_DISCOVERY_RANGE=SYSTEM_DEFAULT
fi
# The Fast DDS profile of the graph (reply writers wait for a new client's reader; see
# config/fastdds.xml); a value already set, even empty (no profile), is kept.
export FASTRTPS_DEFAULT_PROFILES_FILE="${FASTRTPS_DEFAULT_PROFILES_FILE-$_wf_config/fastdds.xml}"
# No shared-memory transport: a SIGKILLed subscriber would stall its publishers for up to 1 s
# (wirefish_bringup.dds_profile); a value already set is kept.
export FASTDDS_BUILTIN_TRANSPORTS="${FASTDDS_BUILTIN_TRANSPORTS-UDPv4}"
unset _wf_root _wf_venv _wf_nounset _wf_config
