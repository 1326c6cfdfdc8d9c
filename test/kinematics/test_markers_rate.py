# SPDX-License-Identifier: Apache-2.0
"""kinematics_node publishes body_wave_markers with every n-th body_wave."""

import pytest

# It mostly waits (0.11 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]
POSE = (0.3, -0.2)
BODY_WAVES = 60  # body_wave messages to observe after the first markers


def stream_until(probe, done) -> None:
    """Publish fresh samples of one pose, 10 ms of sample time apart, until ``done()``."""
    index = 0

    def sent_and_done() -> bool:
        nonlocal index
        probe.send(index, POSE)
        index += 1
        probe.spin(0.01)
        return done()

    probe.wait_for(sent_and_done, 'enough body_wave messages')


@pytest.mark.parametrize(('markers_rate_hz', 'every'), [(10.0, 5), (50.0, 1), (20.0, 2)])
def test_markers_go_out_with_every_nth_body_wave(start_node, probe, markers_rate_hz, every):
    start_node('-p', 'publish_rate_hz:=50.0', '-p', f'markers_rate_hz:={markers_rate_hz}')
    probe.wait_connected()
    stream_until(probe, lambda: probe.markers)
    probe.body.clear()
    probe.markers.clear()
    stream_until(probe, lambda: len(probe.body) >= BODY_WAVES)
    body_stamps = {(m.header.stamp.sec, m.header.stamp.nanosec) for m in probe.body}
    # Markers are reliable, body_wave best effort: the markers of a tick just before the clear
    # may arrive after it, when its body_wave came before; only later ticks are compared.
    marker_stamps = [stamp for stamp in (
        (a.markers[0].header.stamp.sec, a.markers[0].header.stamp.nanosec)
        for a in probe.markers) if stamp >= min(body_stamps)]
    # Each markers array shows the shape of a body_wave tick, and only every n-th tick has one.
    assert set(marker_stamps[:-1]) <= body_stamps
    assert len(marker_stamps) == pytest.approx(len(probe.body) / every, abs=2)
