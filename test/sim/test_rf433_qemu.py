# SPDX-License-Identifier: Apache-2.0
"""
The same scenarios with the ARM build in QEMU behind the rf433 radio model, in gait mode.

One drive of `wirefish up --fish qemu --radio rf433` (40 s by cmd_vel, then a 10 s radio cut
and 8 s after it): the C firmware integrates eq 1, answers GAIT and LINK_CONFIG, coasts and
rests. QEMU has no physics, so there is no ground-truth speed to compare. What it costs: 58 s
of driving, a start-up, and the emulator. Its claims are on the wall clock of the radio and
the emulated board, so it keeps the machine to itself (``keeps_machine``).
"""

import pytest
from radio_run import (board_frames, BoardFrame, cut_figures, describe_link, Drive, drive,
                       SCHEDULE, smooth_bound, worst_step)
from wirefish_bridge.protocol import Status

pytestmark = [pytest.mark.ros, pytest.mark.keeps_machine]

CUT_S = 10.0
AFTER_CUT_S = 8.0
COAST_S = 3.0
LINK_TIMEOUT_S = 1.5


@pytest.fixture(scope='module')
def out(tmp_path_factory):
    return tmp_path_factory.mktemp('rf433_qemu')


@pytest.fixture(scope='module')
def rf433(out) -> Drive:
    record = drive(out, 'rf433', cut_s=CUT_S, after_cut_s=AFTER_CUT_S, qemu=True)
    print(describe_link(record))
    return record


@pytest.fixture(scope='module')
def board(rf433, out) -> list[BoardFrame]:
    return board_frames(out)


def test_qemu_rf433_link_use_stays_under_80_percent_each_way(rf433):
    load = (rf433.radio['load_to_fish'], rf433.radio['load_to_host'])
    print(f"QEMU rf433 gait: {load[0]:.1%} of the preset's rate to the fish, {load[1]:.1%} "
          f'to the host; air time {rf433.radio["use_to_fish"]:.1%} and '
          f'{rf433.radio["use_to_host"]:.1%}')
    assert rf433.at_end_of_drive('drive_mode') == 'gait'
    assert load[0] <= 0.8 and load[1] <= 0.8


def test_qemu_gait_changes_are_acknowledged_quickly(rf433):
    acks = int(rf433.at_end_of_drive('gait_acks'))
    median = float(rf433.at_end_of_drive('gait_ack_median_s'))
    p99 = float(rf433.at_end_of_drive('gait_ack_p99_s'))
    print(f'QEMU rf433 gait: {rf433.at_end_of_drive("gait_changes")} gait changes, '
          f'{rf433.at_end_of_drive("gait_frames_sent")} GAIT frames, {acks} acknowledged: '
          f'median {median:.3f} s, p99 {p99:.3f} s')
    assert acks >= len(SCHEDULE)
    assert median <= 0.3 and p99 <= 1.0


def test_qemu_board_steps_no_servo(rf433, board):
    speed = smooth_bound(rf433)
    driving = [f for f in board if f.t >= rf433.started]
    worst = worst_step(driving, speed)
    stream = [f for f in driving if not f.status & Status.GAIT_MODE]
    print(f'QEMU rf433 gait: {len(driving)} board telemetry frames while driving and through '
          f'the cut, {len(stream)} not in gait mode; smooth bound {speed:.2f} rad/s; largest '
          f'excess {worst:+.4f} rad')
    assert not stream
    assert worst <= 0.0


def test_qemu_radio_cut_coasts_then_rests_then_the_gait_comes_back(rf433, board):
    cut = cut_figures(rf433, board)
    print(cut.line())
    assert abs(cut.coasting_after_s - LINK_TIMEOUT_S) <= 0.5
    assert abs(cut.coast_s - COAST_S) <= 0.3
    assert cut.rest_amplitude < 0.05
    assert cut.link_back_s <= 1.0
    assert cut.gait_back_s <= cut.link_back_s + 1.0
