# SPDX-License-Identifier: Apache-2.0
"""
The order `make test` deals test/'s modules to its workers in: the longest first.

The modules below hold the machine longest (a minute or more each: the ``held_s`` of
``machine_share.jsonl`` in a full run's base temp). `make test` runs test/ as `-n 4 --dist
loadfile --no-loadscope-reorder` on two cores (three slots and a worker for the modules that
barely load the machine), so xdist deals the files in collection order, and conftest.py
collects these first. By default xdist deals the files with most tests first, so these one-test
files came last (the drive, the mission, the two hosts and the fleet once ran after everything
else and test/ took 9.6 min); dealt first, they run side by side while the short files fill the
gaps. The modules that load the machine (``loads_machine``, ``keeps_machine``) run one at a
time, so they are spread among the others, none among the first three (one per worker): a
worker that waits for its turn runs nothing, and a heavy module waiting for its slots holds
the light ones back.
"""

from pathlib import Path

WORKSPACE = Path(__file__).resolve().parents[2]
LONGEST_MODULES = (
    'test/bag/test_recorder_sigkill.py',
    'test/bringup/test_restart.py',
    'test/bridge/test_bridge_pty.py',
    'test/launcher/test_fleet.py',
    'test/launcher/test_two_hosts.py',
    'test/sim/test_rf433_qemu.py',
    'test/firmware_qemu/test_link_in_the_loop.py',
    'test/sim/test_rf433_virtual_fish.py',
    'test/bringup/test_whole_graph.py',
    'test/view/test_foxglove_clients.py',
    'test/bag/test_loaded_recording.py',
    'test/test_repeated_signals.py',
    'test/tuner/test_retune_action.py',
    'test/firmware_qemu/test_graph_on_qemu.py',
    'test/operator/test_topic_param_commands.py',
    'test/view/test_view_protocol.py',
    'test/view/test_dashboard_browser.py',
)


_RANKS = {WORKSPACE / name: i for i, name in enumerate(LONGEST_MODULES)}


def module_rank(path: Path) -> int:
    """Return where a test module is dealt: its place in ``LONGEST_MODULES``, else after them."""
    return _RANKS.get(Path(path), len(_RANKS))
