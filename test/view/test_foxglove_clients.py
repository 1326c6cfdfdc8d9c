# SPDX-License-Identifier: Apache-2.0
"""
`wirefish up --sim --view` seen by the clients a ROS user brings, and clients kept apart.

One graph for the module (on simulated time, ``--speed 1``). The claims: Foxglove's own client
library (`@foxglove/ws-protocol`'s FoxgloveClient, offering its default subprotocol
``foxglove.websocket.v1``, run by node from the dashboard's npm packages) lists every channel and
decodes 20 s of each, the periodic ones at their nominal rates (+-5 %) in the messages' own time
(the wall-time rates are printed: they follow the machine's real-time factor); a handshake
offering neither name is refused with HTTP 400 and the offered and supported names in the view's
log; 5,000 refused messages from one client leave a bystander connected, without a status of the
flooder's, with servo_cmd at >= 95 Hz; the services' schemas are the ROS types' and a malformed
request fails with the reason.
"""

import json
from pathlib import Path
import shutil
import struct
import subprocess
import time

from foxglove_client import FoxgloveClient
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect
from wirefish_bringup.graph import default_params_file
import yaml

pytestmark = pytest.mark.ros

CLIENT_SCRIPT = Path(__file__).with_name('ws_protocol_client.js')
NODE = shutil.which('node')
WARMUP_S, WINDOW_S = 4.0, 20.0
WALL_LIMIT_S = 120.0  # a loaded machine runs the simulated clock slower than the wall's
RATE_TOLERANCE = 0.05


def _parameter(node: str, name: str) -> float:
    """Return a rate from the default params file (the graph the fixture runs)."""
    values = yaml.safe_load(default_params_file().read_text())
    return float(values[f'/**/{node}']['ros__parameters'][name])


def nominal_rates(namespace: str) -> dict[str, float]:
    """Return the periodic channels and their rates (Hz), from the parameters that set them."""
    servo = _parameter('cpg_node', 'publish_rate_hz')
    wave = _parameter('kinematics_node', 'publish_rate_hz')
    rates = {
        'servo_cmd': servo,
        # The board's telemetry answers each command: one frame per servo command.
        'servo_state': servo, 'imu/data': servo, 'attitude': servo,
        'body_wave': wave,
        'body_wave_markers': 10.0,  # kinematics_node's markers_rate_hz default
        'planner_state': 20.0,  # planner_node's control_rate_hz default (cpg_command too,
        # but only from the first cmd_vel on)
        'battery': _parameter('bridge_node', 'battery_rate_hz'),
        'sim/ground_truth': 50.0,  # fish_sim's ground truth rate
    }
    found = {f'{namespace}/{topic}': rate for topic, rate in rates.items()}
    # /diagnostics: bridge_node's and planner_node's, at the same rate each.
    found['/diagnostics'] = 2 * _parameter('bridge_node', 'diagnostics_rate_hz')
    # /tf: tf_node's odom -> base_link (one per ground truth, 50 Hz) and tail frames (one per
    # body_wave).
    found['/tf'] = 50.0 + wave
    return found


def test_foxglove_ws_protocol_client_decodes_every_channel_at_its_rate(view_graph, tmp_path):
    assert NODE, 'node is needed (the dashboard is built with it)'
    namespace = view_graph.graph.namespace
    # Every channel is advertised before the client connects, so it subscribes to all at once.
    probe = FoxgloveClient(view_graph.ws_url)
    try:
        assert probe.wait(lambda: set(nominal_rates(namespace)) <= {
            c['topic'] for c in probe.channels.values()}, timeout_s=30.0), sorted(
            set(nominal_rates(namespace)) - {c['topic'] for c in probe.channels.values()})
    finally:
        probe.close()
    out = tmp_path / 'client.json'
    run = subprocess.run([NODE, '--experimental-websocket', str(CLIENT_SCRIPT), view_graph.ws_url,
                          str(WARMUP_S), str(WINDOW_S), str(WALL_LIMIT_S),
                          f'{namespace}/servo_cmd', str(out)],
                         capture_output=True, text=True, timeout=WALL_LIMIT_S + 60)
    assert run.returncode == 0, run.stdout + run.stderr + (out.read_text()[:2000]
                                                           if out.exists() else '')
    result = json.loads(out.read_text())
    assert result['subprotocol'] == 'foxglove.websocket.v1'
    channels = result['channels']
    # The window in the messages' own time (the graph's clock: simulated at --speed 1), from
    # half a second after servo_cmd's latest stamp at the end of the warm-up.
    start = result['start'] + 0.5
    end = start + WINDOW_S
    rates = {topic: sum(start <= t < end for t in c['stamps']) / WINDOW_S
             for topic, c in channels.items()}
    print(f'{WINDOW_S:g} s of stamps took {result["wallS"]:.1f} s of wall time')
    for topic, channel in sorted(channels.items()):
        print(f'{topic}: {rates[topic]:6.1f} Hz of its own time, '
              f'{channel["wallCount"] / result["wallS"]:6.1f} Hz of wall time, '
              f'{channel["received"]} decoded, {channel["failures"]} failures '
              f'({channel["encoding"]} {channel["schemaName"]})')
    assert {t: c['firstError'] for t, c in channels.items() if c['failures']} == {}
    assert f'{namespace}/view/scene' in channels and f'{namespace}/view/retune' in channels
    assert channels[f'{namespace}/view/scene']['received'] > 0
    # /tf is shared by every graph of the ROS domain and its frames carry no namespace: this
    # graph's share is at least its nominal rate (equal when it is alone on the domain).
    off = {topic: (round(rates[topic], 2), rate)
           for topic, rate in nominal_rates(namespace).items()
           if rates[topic] < (1 - RATE_TOLERANCE) * rate or (
               topic != '/tf' and rates[topic] > (1 + RATE_TOLERANCE) * rate)}
    assert off == {}, f'measured, nominal (Hz): {off}'
    # The latched ones were decoded too.
    assert channels[f'{namespace}/cpg_params']['received'] >= 1
    assert channels['/tf_static']['received'] >= 1


def test_a_handshake_offering_neither_name_is_refused_and_logged(view_graph):
    with pytest.raises(InvalidStatus) as refused:
        connect(view_graph.ws_url, subprotocols=['foxglove.websocket.v2'], open_timeout=10)
    assert refused.value.response.status_code == 400
    body = refused.value.response.body.decode()
    assert "offered subprotocols ['foxglove.websocket.v2']" in body
    assert "'foxglove.sdk.v1', 'foxglove.websocket.v1'" in body
    logs = list(view_graph.graph.out_dir.rglob('view_node*.log'))
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline and not any(
            'foxglove.websocket.v2' in p.read_text() for p in logs):
        time.sleep(0.2)
    assert any("offered subprotocols ['foxglove.websocket.v2']" in p.read_text()
               for p in logs), logs


def _header_stamp_s(cdr: bytes) -> float:
    """Return the header stamp (s) of a CDR message that starts with a std_msgs/Header."""
    sec, nanosec = struct.unpack_from('<iI', cdr, 4)  # after the 4-byte encapsulation header
    return sec + nanosec * 1e-9


def test_a_flood_of_refused_messages_reaches_neither_a_bystander_nor_its_stream(view_graph):
    namespace = view_graph.graph.namespace
    servo_cmd = f'{namespace}/servo_cmd'
    bystander = FoxgloveClient(view_graph.ws_url)
    flooder = FoxgloveClient(view_graph.ws_url)
    try:
        assert bystander.wait(lambda: bystander.channel_of(servo_cmd) is not None, 30.0)
        subscription = bystander.subscribe(bystander.channel_of(servo_cmd)['id'])
        assert bystander.wait(lambda: len(bystander.messages.get(subscription, [])) > 100, 20.0)
        channel = flooder.advertise(servo_cmd, 'json', 'sensor_msgs/msg/JointState')
        start = time.monotonic()
        with bystander.lock:
            before = len(bystander.messages[subscription])
        for _ in range(5000):
            flooder.ws.send(struct.pack('<BI', 1, channel) + b'{"position": [1.0, 1.0]}')
        # Then the bystander's stream over a window that starts with the flood.
        time.sleep(max(0.0, 5.0 - (time.monotonic() - start)))
        elapsed = time.monotonic() - start
        with bystander.lock:
            during = [payload for _, payload in bystander.messages[subscription][before:]]
        # In the graph's own time (its stamps: simulated at --speed 1) and in wall time.
        stamps = [_header_stamp_s(payload) for payload in during]
        rate = (len(stamps) - 1) / (max(stamps) - min(stamps))
        print(f'flood: 5000 refused in {elapsed:.1f} s; the bystander had servo_cmd at '
              f'{rate:.1f} Hz of its stamps ({len(during) / elapsed:.1f} Hz of wall time), '
              f'{len(bystander.statuses)} statuses; the flooder {len(flooder.statuses)} '
              'statuses')
        assert not bystander.closed and rate >= 95.0
        assert flooder.wait(lambda: any('refused' in s['message'] for s in flooder.statuses),
                            10.0)
        assert [s for s in bystander.statuses if 'refused' in s['message']] == []
        # Rate-limited per client and reason: a handful, not thousands.
        assert len(flooder.statuses) <= 2 + 2 * elapsed
    finally:
        flooder.close()
        bystander.close()


class _ServiceClient(FoxgloveClient):
    """The tests' client, also keeping each failed service call's message."""

    def __init__(self, url: str) -> None:
        self.failures: dict[int, str] = {}
        super().__init__(url)

    def _on_text(self, op: dict) -> None:
        if op['op'] == 'serviceCallFailure':
            with self.lock:
                self.failures[op['callId']] = op['message']
        super()._on_text(op)


def _schema(service: dict, part: str) -> dict:
    return json.loads(service[part]['schema'])


def test_service_schemas_are_the_ros_types_and_a_malformed_request_fails(view_graph):
    namespace = view_graph.graph.namespace
    client = _ServiceClient(view_graph.ws_url)
    try:
        names = {f'{namespace}/{s}' for s in ('start', 'stop', 'follow_commands', 'retune_gait')}
        assert client.wait(lambda: names <= set(client.services), 30.0)
        retune = client.services[f'{namespace}/retune_gait']
        assert retune['request']['schemaEncoding'] == 'jsonschema'
        goal = _schema(retune, 'request')['properties']
        assert set(goal) == {'wave', 'apply', 'seed', 'max_iterations', 'swarm_size', 'mode',
                             'use_library'}
        assert set(goal['wave']['properties']) == {'c1', 'c2', 'k', 'frequency_hz'}
        assert goal['max_iterations'] == {'type': 'integer', 'minimum': 0,
                                          'maximum': 2**32 - 1}
        start = client.services[f'{namespace}/start']
        assert _schema(start, 'request')['properties'] == {}
        assert _schema(start, 'response')['properties'] == {
            'success': {'type': 'boolean'}, 'message': {'type': 'string'}}
        calls = {
            client.call(f'{namespace}/start', b'{nope'): 'start: not JSON',
            client.call(f'{namespace}/start', b'{"now": true}'): 'start: request: no field now',
            client.call(f'{namespace}/retune_gait', b'{"wave": {"c1": "abc"}}'):
                'retune_gait: wave.c1 must be a finite number, got "abc"',
            client.call(f'{namespace}/retune_gait', b'{"max_iterations": -1}'):
                'retune_gait: max_iterations must be a whole number'}
        assert client.wait(lambda: set(calls) <= set(client.failures), 20.0), client.failures
        for call, reason in calls.items():
            assert reason in client.failures[call], client.failures[call]
        assert not set(calls) & set(client.responses)
        good = client.call(f'{namespace}/start', b'{}')
        assert client.wait(lambda: good in client.responses, 20.0)
        assert json.loads(client.responses[good])['success'] is True
    finally:
        client.close()
