# SPDX-License-Identifier: Apache-2.0
"""
bridge_node in gait mode, against a fish the test plays on a pty.

cpg_params becomes a GAIT (and never a SERVO_CMD), LINK_CONFIG goes out at link-up until an ACK
accepts it, then the GAIT (not before: the fish must run the configured link), resent until
acknowledged, COASTING shows in /diagnostics, compact
telemetry is published in SI units. Stream mode on a link the bridge configures sends no
SERVO_CMD before that ACK either.
"""

import dataclasses
import time

import pytest
from wirefish_bridge.gait_link import GaitParameters
from wirefish_bridge.protocol import (Ack, Gait, LinkConfig, MsgType, ServoCommand, Status,
                                      Telemetry, TelemetryCompact, TelemetryForm)
from wirefish_common.qos import LATCHED
from wirefish_msgs.msg import CpgParams

# It mostly waits (0.21 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

PARAMS = GaitParameters(1.2, (0.3, 0.4), (0.05, 0.05), 4.0, 4.0, -0.6, 0.6, 20.0)
TELEMETRY = Telemetry(board_time_ms=0, roll=0.0, pitch=0.0, yaw=0.1, gyro=(0.0, 0.0, 0.0),
                      accel=(0.0, 0.0, 9.8), servo_1=0.1, servo_2=-0.2, battery_v=8.0,
                      status=int(Status.GAIT_MODE), gait_id=1)


def _cpg_params() -> CpgParams:
    return CpgParams(frequency_hz=PARAMS.frequency_hz, amplitude=list(PARAMS.amplitude),
                     offset=list(PARAMS.offset), w12=PARAMS.w12, w21=PARAMS.w21,
                     phi12=PARAMS.phi12, phi21=PARAMS.phi21, alpha=PARAMS.alpha)


def _until(probe, fake_device, predicate, timeout_s: float, heartbeat: bool = True) -> list:
    """Spin, keep the fish identified, collect what the bridge sent until ``predicate(sent)``."""
    sent: list = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and not predicate(sent):
        if heartbeat:
            fake_device.send_fish_heartbeat()
        probe.spin_for(0.1)
        sent += fake_device.messages()
    return sent


def test_gait_mode_sends_gaits_and_its_link_config_until_acknowledged(fake_device, start_bridge,
                                                                      probe):
    start_bridge(fake_device.link, 'drive_mode:=gait', 'telemetry_period_s:=0.1',
                 'telemetry_form:=compact', 'gait_resend_s:=0.3')
    publisher = probe.node.create_publisher(CpgParams, 'cpg_params', LATCHED)
    publisher.publish(_cpg_params())
    # LINK_CONFIG first, resent while unacknowledged; no GAIT before the fish runs that link.
    sent = _until(probe, fake_device,
                  lambda s: sum(isinstance(m, LinkConfig) for m in s) >= 2, 20.0)
    configs = [m for m in sent if isinstance(m, LinkConfig)]
    assert len(configs) >= 2 and not any(isinstance(m, Gait) for m in sent), sent
    assert configs[0] == LinkConfig(100, TelemetryForm.COMPACT, 2000, 1500, 3000)
    fake_device.send(Ack(MsgType.LINK_CONFIG, _last_seq(fake_device, LinkConfig)))
    # Then the GAIT, resent while unacknowledged.
    sent = _until(probe, fake_device, lambda s: sum(isinstance(m, Gait) for m in s) >= 2, 20.0)
    gaits = [m for m in sent if isinstance(m, Gait)]
    assert len(gaits) >= 2 and not any(isinstance(m, LinkConfig) for m in sent), sent
    assert gaits[0].gait_id == 1   # float32 on the wire:
    assert gaits[0].to_wire()[1:] == pytest.approx(PARAMS.message(1).to_wire()[1:], abs=1e-6)
    assert not any(isinstance(m, ServoCommand) for m in sent)

    # The fish answers: the resends stop, the gait is acknowledged.
    fake_device.send(Ack(MsgType.GAIT, _last_seq(fake_device, Gait)))
    compact = TelemetryCompact.from_telemetry(TELEMETRY)
    for _ in range(20):
        fake_device.send_fish_heartbeat()
        fake_device.send(compact)
        probe.spin_for(0.1)
    after = fake_device.messages()
    values = probe.last_diagnostics()
    print(f'gait mode: {len(gaits)} GAIT, {len(configs)} LINK_CONFIG before the ACKs; after: '
          f'{sorted({type(m).__name__ for m in after})}; diagnostics {values.get("drive_mode")}, '
          f'gait {values.get("gait_id")} acknowledged {values.get("gait_acknowledged")}, '
          f'link config {values.get("link_config_acknowledged")}')
    assert not any(isinstance(m, (Gait, LinkConfig, ServoCommand)) for m in after)
    assert values['drive_mode'] == 'gait'
    assert values['gait_acknowledged'] == 'True'
    assert values['link_config_acknowledged'] == 'True'
    assert probe.servo and abs(probe.servo[-1].position[1] - (-0.2)) < 1e-4   # compact, in rad

    # The board coasts: /diagnostics says so.
    for _ in range(15):
        fake_device.send_fish_heartbeat()
        coasting = dataclasses.replace(TELEMETRY, status=int(Status.GAIT_MODE | Status.COASTING))
        fake_device.send(TelemetryCompact.from_telemetry(coasting))
        probe.spin_for(0.1)
    status = probe.statuses()[-1]
    assert status.level == b'\x01' and 'COASTING' in status.message


def test_stream_mode_on_a_configured_link_streams_only_once_the_fish_acknowledges_it(
        fake_device, start_bridge, probe):
    start_bridge(fake_device.link, 'drive_mode:=stream', 'telemetry_period_s:=0.1',
                 'telemetry_form:=compact', 'gait_resend_s:=0.3')
    # Neither servo_cmd's neutral before the first servo_cmd nor anything else but the
    # LINK_CONFIG (and heartbeats, READs) goes out before its ACK.
    sent = _until(probe, fake_device,
                  lambda s: sum(isinstance(m, LinkConfig) for m in s) >= 3, 20.0)
    print(f'stream mode before the ACK: {sorted({type(m).__name__ for m in sent})}')
    assert not any(isinstance(m, (ServoCommand, Gait)) for m in sent), sent
    fake_device.send(Ack(MsgType.LINK_CONFIG, _last_seq(fake_device, LinkConfig)))
    sent = _until(probe, fake_device,
                  lambda s: sum(isinstance(m, ServoCommand) for m in s) >= 5, 20.0)
    assert sum(isinstance(m, ServoCommand) for m in sent) >= 5
    # /diagnostics comes at its own rate: wait for one that says so.
    _until(probe, fake_device, lambda _: bool(probe.statuses())
           and probe.last_diagnostics()['link_configured'] == 'True', 10.0)
    assert probe.last_diagnostics()['link_configured'] == 'True'


def _last_seq(fake_device, kind: type) -> int:
    """Return the sequence number of the last frame of ``kind`` the bridge wrote."""
    from wirefish_bridge.codec import StreamDecoder

    decoder = StreamDecoder()
    frames = [f for f in decoder.feed(bytes(fake_device.received))
              if isinstance(f.message, kind)]
    return frames[-1].seq
