# SPDX-License-Identifier: Apache-2.0
"""
view_node: a Foxglove WebSocket server over the fish's graph, and the dashboard's web server.

Channels (protocol ``foxglove.sdk.v1``, also offered as ``foxglove.websocket.v1``)
    Every topic of the graph in the node's namespace, and ``/tf``, ``/tf_static`` and
    ``/diagnostics``: one CDR channel each with its ``ros2msg`` schema, found by a discovery
    tick (``discovery_period_s``). A topic is subscribed (raw bytes: nothing is decoded) only
    while a client subscribes to its channel; its QoS follows its publishers' (best effort,
    transient local), found again each discovery tick (a latched topic whose publisher is
    found after the client subscribed still delivers its message). ``view/scene``
    (foxglove.SceneUpdate): the fish (``scene``), at ``scene_rate_hz`` while a client watches
    it (body_wave and /tf decoded only then; the trail is this fish's odom -> base_link from
    then on). ``view/retune`` (JSON): the retune goal's progress and result.
Client publish
    Accepted on ``cmd_vel`` (geometry_msgs/msg/Twist, CDR or JSON) within ``max_speed`` and
    ``max_turn`` (`wirefish drive`'s limits); any other channel, or a message outside the
    limits or malformed, is refused: a warning in the log and a status message to the client
    that sent it, rate-limited per client and kind of refusal (``front_door``).
Services (JSON)
    ``start``, ``stop`` (std_srvs/Trigger of cpg_node; stop also sends cmd_vel zero first, so
    the planner rests the fish), ``follow_commands`` (cpg_node's: hands the gait back to the
    planner after a manual override such as an applied retune, as `wirefish hand-back` does),
    ``retune_gait`` (sends the tuner's action goal; its progress
    and result go out on ``view/retune``). Their schemas are JSON Schemas generated from the
    ROS types (``json_messages``: Trigger's request and response; RetuneGait's goal, answered
    as a Trigger response); a request that is not JSON or not of the type fails the call
    with the reason.
The dashboard
    ``http://address:http_port/``: the bundled page (``share/wirefish_view/dashboard``, built by
    `make setup`) and ``/config.json`` (the WebSocket port and namespace); 0 serves none.
Parameters: ``address`` (127.0.0.1; anything wider is logged as a warning), ``port``,
``http_port``, ``max_speed``, ``max_turn``, ``scene_rate_hz``, ``trail_length``,
``discovery_period_s``, ``frame_prefix``, l1 and l2 (the graph's geometry block); the table
is ``view_node_parameters``.
"""

from __future__ import annotations

from concurrent.futures import Future as ConcurrentFuture
from functools import partial
import importlib
import ipaddress
import json
import math
import queue
import threading
import time
from typing import Any

import foxglove
from foxglove.channels import SceneUpdateChannel
from foxglove.websocket import Capability, ChannelView, Client, ServerListener
from geometry_msgs.msg import Twist
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage
from wirefish_common.frames import declare_frame_prefix, prefixed
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import InvalidParameters, NodeParameters
from wirefish_common.qos import RELIABLE, SENSOR_DATA, TF
from wirefish_msgs.action import RetuneGait
from wirefish_msgs.msg import BodyWave
from wirefish_view.client_input import check_advertised, cmd_vel_from_client
from wirefish_view.errors import RefusedInput, UnknownType
from wirefish_view.front_door import FrontDoor
from wirefish_view.json_messages import from_json, json_schema
from wirefish_view.scene import fish_scene, tail_segments
from wirefish_view.schemas import ros2msg_schema
from wirefish_view.view_node_parameters import TABLE
from wirefish_view.web import DashboardServer

GLOBAL_TOPICS = ('/tf', '/tf_static', '/diagnostics')
SERVICE_WAIT_S = 5.0
# view/retune: state sent | running (iteration, max_iterations, best_loss) | rejected | done
# (success, message, applied, loss, iterations, from_library, rmse_theta_deg).
RETUNE_PROGRESS_SCHEMA = json.dumps({
    'type': 'object', 'properties': {
        'state': {'enum': ['sent', 'running', 'rejected', 'done']},
        'iteration': {'type': 'integer'}, 'max_iterations': {'type': 'integer'},
        'best_loss': {'type': 'number'}, 'success': {'type': 'boolean'},
        'message': {'type': 'string'}, 'applied': {'type': 'boolean'},
        'loss': {'type': ['number', 'null']}, 'iterations': {'type': 'integer'},
        'from_library': {'type': 'boolean'},
        'rmse_theta_deg': {'type': 'array', 'items': {'type': ['number', 'null']}}}}).encode()


def is_loopback(address: str) -> bool:
    """Return whether ``address`` binds this machine only (127.0.0.0/8, ::1, localhost)."""
    if address == 'localhost':
        return True
    try:
        return ipaddress.ip_address(address).is_loopback
    except ValueError:
        return False


def _qos_of(publishers: list) -> QoSProfile:
    """
    Return a subscription QoS that matches every publisher of a topic.

    None discovered yet: best effort, which matches a publisher of either reliability (a
    reliable reader would get nothing from a best-effort stream discovered a moment later).
    """
    best_effort = not publishers or any(
        p.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT for p in publishers)
    latched = publishers and all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
                                 for p in publishers)
    if best_effort:
        return SENSOR_DATA
    return QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                      durability=(DurabilityPolicy.TRANSIENT_LOCAL if latched
                                  else DurabilityPolicy.VOLATILE))


def resubscribe_qos(held: QoSProfile, publishers: list) -> QoSProfile | None:
    """
    Return the QoS a topic's subscription should be made again with, or None to keep ``held``.

    A subscription made before its topic's publishers were discovered is best effort and
    volatile (``_qos_of``): it matches any publisher, but a latched one's message, published
    before the match, never reaches it. Once publishers are known and want another QoS, the
    subscription is made again with theirs (a latched topic then delivers its message). With no
    publisher known (one restarting) the held QoS stays.
    """
    if not publishers:
        return None
    wanted = _qos_of(publishers)
    if (wanted.reliability, wanted.durability) == (held.reliability, held.durability):
        return None
    return wanted


class ViewNode(Node):
    """The graph as Foxglove channels; cmd_vel, start/stop and retune from the clients."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters, start the servers, wire discovery, scene and services."""
        super().__init__('view_node', **kwargs)
        # Read once: the servers, the timers and the dashboard's limits are built from these,
        # so a later set is judged (refused if invalid) but not applied.
        self._node_parameters = NodeParameters(self, TABLE)
        self._values = dict(self._node_parameters.values)
        prefix = declare_frame_prefix(self)
        self._frames = {f: prefixed(prefix, f) for f in ('odom', 'base_link', 'tail_base')}
        namespace = self.get_namespace().rstrip('/')
        self._namespace = namespace
        self._cmd_vel_topic = f'{namespace}/cmd_vel'
        self._channels: dict[str, foxglove.Channel] = {}
        self._subscribers: dict[str, int] = {}  # topic -> clients subscribed
        self._raw_subscriptions: dict[str, tuple[Any, QoSProfile]] = {}  # with its QoS
        self._requests: queue.Queue[tuple[str, str]] = queue.Queue()
        self._trail: list[tuple[float, float]] = []
        self._segments: list[tuple[list[float], list[float]]] = []
        self._scene_inputs: list[Any] = []  # body_wave and /tf, while the scene is watched
        self._cmd_pub = self.create_publisher(Twist, 'cmd_vel', RELIABLE)
        self._start_client = self.create_client(Trigger, 'start')
        self._stop_client = self.create_client(Trigger, 'stop')
        self._follow_client = self.create_client(Trigger, 'cpg_node/follow_commands')
        self._retune = ActionClient(self, RetuneGait, 'retune_gait')
        self._retune_busy = threading.Event()
        self._start_servers()
        self.create_timer(self._values['discovery_period_s'], self._discover)
        self.create_timer(0.05, self._serve_requests)
        self.create_timer(1.0 / self._values['scene_rate_hz'], self._publish_scene)
        self._discover()

    # --- servers --------------------------------------------------------------------------
    def _start_servers(self) -> None:
        address = self._values['address']
        if not is_loopback(address):
            self.get_logger().warn(
                f'binding {address}: the view (and cmd_vel to the fish) is open to every '
                'machine that reaches this one; use 127.0.0.1 unless that is meant')
        self._fox_context = foxglove.Context()
        self._scene = SceneUpdateChannel(f'{self._namespace}/view/scene',
                                         context=self._fox_context)
        self._retune_channel = foxglove.Channel(
            f'{self._namespace}/view/retune', message_encoding='json', context=self._fox_context,
            schema=foxglove.Schema(name='wirefish_view/RetuneProgress', encoding='jsonschema',
                                   data=RETUNE_PROGRESS_SCHEMA))
        services = [self._service('start', self._start_client),
                    self._service('stop', self._stop_client),
                    self._service('follow_commands', self._follow_client),
                    foxglove.Service(f'{self._namespace}/retune_gait', schema=_service_schema(
                        'wirefish_msgs/action/RetuneGait', RetuneGait.Goal, Trigger.Response),
                        handler=self._on_retune)]
        # The sdk's server on a loopback port of its own; the view's port is the front door's,
        # which speaks either subprotocol name and answers client publishing per client.
        self._server = foxglove.start_server(
            name=f'wirefish {self._namespace or "/"}', host='127.0.0.1', port=0,
            capabilities=[Capability.ClientPublish, Capability.Services],
            supported_encodings=['cdr', 'json'], server_listener=_Listener(self),
            services=services,
            context=self._fox_context)
        self._web = None
        try:
            self._front = FrontDoor(address, self._values['port'], self._server.port, self,
                                    self.get_logger().warn)
        except OSError as error:
            self._server.stop()
            raise _unbound('port', address, self._values['port'], error) from None
        if self._values['http_port'] >= 0:
            try:
                self._web = DashboardServer(address, self._values['http_port'], {
                    'websocket_port': self._front.port, 'namespace': self._namespace,
                    'max_speed': self._values['max_speed'],
                    'max_turn': self._values['max_turn'], 'frames': self._frames})
            except OSError as error:
                self._front.stop()
                self._server.stop()
                raise _unbound('http_port', address, self._values['http_port'], error) from None
        self.get_logger().info(
            f'Foxglove WebSocket ws://{address}:{self._front.port}'
            + (f', dashboard http://{address}:{self._web.port}/' if self._web else ''))

    def _service(self, name: str, client: Any) -> foxglove.Service:
        return foxglove.Service(f'{self._namespace}/{name}',
                                schema=_service_schema('std_srvs/srv/Trigger', Trigger.Request,
                                                       Trigger.Response),
                                handler=partial(self._on_trigger, name, client))

    def destroy_node(self) -> None:
        """Stop the servers, then the node."""
        self._front.stop()
        self._server.stop()
        if self._web is not None:
            self._web.stop()
        super().destroy_node()

    # --- discovery and subscriptions (executor thread) -----------------------------------
    def _wanted(self, topic: str) -> bool:
        if topic in GLOBAL_TOPICS:
            return True
        inside = topic.startswith(f'{self._namespace}/')
        return inside and '/_' not in topic and not topic.startswith(
            f'{self._namespace}/view/')

    def _discover(self) -> None:
        for topic, (_, held) in list(self._raw_subscriptions.items()):
            qos = resubscribe_qos(held, self.get_publishers_info_by_topic(topic))
            if qos is not None:
                self.destroy_subscription(self._raw_subscriptions.pop(topic)[0])
                self._subscribe_raw(topic, qos)
                self.get_logger().info(
                    f'{topic}: subscribed again as its publishers offer '
                    f'({qos.reliability.name.lower()}, {qos.durability.name.lower()})')
        for topic, types in self.get_topic_names_and_types():
            if topic in self._channels or not self._wanted(topic) or len(types) != 1:
                continue
            try:
                schema = ros2msg_schema(types[0])
            except UnknownType as error:
                self.get_logger().warn(f'{topic} not offered: {error}', once=True)
                continue
            self._channels[topic] = foxglove.Channel(
                topic, message_encoding='cdr', context=self._fox_context,
                schema=foxglove.Schema(name=types[0], encoding='ros2msg',
                                       data=schema.encode()))

    def _serve_requests(self) -> None:
        while True:
            try:
                kind, topic = self._requests.get_nowait()
            except queue.Empty:
                return
            count = self._subscribers.get(topic, 0) + (1 if kind == 'subscribe' else -1)
            self._subscribers[topic] = max(count, 0)
            if topic == self._scene.topic():
                self._watch_scene(count > 0)
            elif count > 0 and topic not in self._raw_subscriptions and topic in self._channels:
                self._subscribe_raw(topic, _qos_of(self.get_publishers_info_by_topic(topic)))
            elif count <= 0 and topic in self._raw_subscriptions:
                self.destroy_subscription(self._raw_subscriptions.pop(topic)[0])

    def _subscribe_raw(self, topic: str, qos: QoSProfile) -> None:
        channel = self._channels[topic]
        self._raw_subscriptions[topic] = (self.create_subscription(
            _type_of(channel), topic, partial(self._forward, channel), qos, raw=True), qos)

    def _forward(self, channel: foxglove.Channel, data: bytes) -> None:
        channel.log(data, log_time=time.time_ns())

    # --- the server's callbacks (its threads) ---------------------------------------------
    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        """Subscribe to the ROS topic of a channel a client subscribed."""
        self._requests.put(('subscribe', channel.topic))

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        """Drop the ROS subscription once no client wants it."""
        self._requests.put(('unsubscribe', channel.topic))

    # --- client publishing (the front door's thread) --------------------------------------
    def check_channel(self, topic: str, encoding: str, schema_name: str) -> None:
        """Raise ``RefusedInput`` unless the channel is this graph's cmd_vel as a Twist."""
        check_advertised(topic, encoding, schema_name, self._cmd_vel_topic)

    def publish(self, encoding: str, data: bytes) -> None:
        """Publish a client's cmd_vel once validated; raise ``RefusedInput`` otherwise."""
        command = cmd_vel_from_client(encoding, data, self._values['max_speed'],
                                      self._values['max_turn'])
        twist = Twist()
        twist.linear.x, twist.angular.z = command.speed, command.turn
        self._cmd_pub.publish(twist)

    # --- services (the server's threads) --------------------------------------------------
    def _on_trigger(self, name: str, client: Any, request: Any) -> bytes:
        try:
            from_json(Trigger.Request, request.payload)  # a Trigger request has no field
        except RefusedInput as error:
            raise RefusedInput(f'{name}: {error}') from None  # the caller's call fails
        if name == 'stop':
            self._cmd_pub.publish(Twist())  # the planner rests the fish at once
        if not client.wait_for_service(timeout_sec=SERVICE_WAIT_S):
            return _answer(False, f'{name}: cpg_node does not offer it')
        done = threading.Event()
        future = client.call_async(Trigger.Request())
        future.add_done_callback(lambda _: done.set())
        if not done.wait(SERVICE_WAIT_S):
            return _answer(False, f'{name}: no answer in {SERVICE_WAIT_S:g} s')
        result = future.result()
        return _answer(result.success, result.message)

    def _on_retune(self, request: Any) -> bytes:
        try:
            goal = from_json(RetuneGait.Goal, request.payload)
        except RefusedInput as error:
            raise RefusedInput(f'retune_gait: {error}') from None  # the caller's call fails
        if self._retune_busy.is_set():
            return _answer(False, 'retune: a fit is already running')
        if not self._retune.wait_for_server(timeout_sec=SERVICE_WAIT_S):
            return _answer(False, 'retune: tuner_node does not offer retune_gait')
        # rclpy's ActionClient files a goal's future under its request only after sending the
        # request. Sent from this (the server's) thread, an answer the executor took in between
        # was dropped ("Ignoring unexpected goal response") and the fit never reported back.
        # The executor's own thread sends it: no answer can be taken before it is filed.
        executor = self.executor
        if executor is None:  # the node is being taken down
            return _answer(False, 'retune: the view is stopping')
        self._retune_busy.set()
        self._report_retune({'state': 'sent'})
        executor.create_task(partial(self._send_retune, goal))
        return _answer(True, 'goal sent: progress on view/retune')

    def _send_retune(self, goal: Any) -> None:
        sent = self._retune.send_goal_async(goal, feedback_callback=self._on_retune_feedback)
        sent.add_done_callback(self._on_retune_answer)

    def _report_retune(self, report: dict) -> None:
        # JSON has no NaN (Python's json writes it, a browser's JSON.parse refuses it): a
        # refused wave's loss and RMSE, never computed, go out as null.
        self._retune_channel.log(json.dumps(_json_safe(report), allow_nan=False).encode(),
                                 log_time=time.time_ns())

    def _on_retune_feedback(self, message: Any) -> None:
        f = message.feedback
        self._report_retune({'state': 'running', 'iteration': f.iteration,
                             'max_iterations': f.max_iterations, 'best_loss': f.best_loss})

    def _on_retune_answer(self, future: ConcurrentFuture) -> None:
        handle = future.result()
        if not handle.accepted:
            self._retune_busy.clear()
            self._report_retune({'state': 'rejected'})
            return
        handle.get_result_async().add_done_callback(self._on_retune_result)

    def _on_retune_result(self, future: ConcurrentFuture) -> None:
        r = future.result().result
        self._retune_busy.clear()
        self._report_retune({'state': 'done', 'success': r.success, 'message': r.message,
                             'applied': r.applied, 'loss': r.loss,
                             'iterations': r.iterations, 'from_library': r.from_library,
                             'rmse_theta_deg': list(r.rmse_theta_deg)})

    # --- the scene (decoded inputs only while a client watches it) ------------------------
    def _watch_scene(self, watched: bool) -> None:
        if watched and not self._scene_inputs:
            self._scene_inputs = [
                self.create_subscription(BodyWave, 'body_wave', self._on_body_wave,
                                         SENSOR_DATA),
                self.create_subscription(TFMessage, '/tf', self._on_tf, TF)]
        elif not watched:
            for subscription in self._scene_inputs:
                self.destroy_subscription(subscription)
            self._scene_inputs, self._segments = [], []

    def _on_body_wave(self, msg: BodyWave) -> None:
        self._segments = tail_segments(msg.q, msg.x, msg.y, self._values['l1'],
                                       self._values['l2'])

    def _on_tf(self, msg: TFMessage) -> None:
        """Extend the trail with this fish's odom -> base_link (virtual or dead-reckoned)."""
        for t in msg.transforms:
            if (t.header.frame_id, t.child_frame_id) != (self._frames['odom'],
                                                         self._frames['base_link']):
                continue
            p = t.transform.translation
            if math.isfinite(p.x) and math.isfinite(p.y):
                self._trail.append((p.x, p.y))
                del self._trail[:-self._values['trail_length']]

    def _publish_scene(self) -> None:
        if self._segments:
            self._scene.log(fish_scene(time.time_ns(), self._frames, self._segments,
                                       self._trail))


class _Listener(ServerListener):
    """The server's callbacks, handed to the node."""

    def __init__(self, node: ViewNode) -> None:
        self._node = node

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        self._node.on_subscribe(client, channel)

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        self._node.on_unsubscribe(client, channel)


def _type_of(channel: foxglove.Channel) -> type:
    """Return the message class of a channel's schema name (``pkg/msg/Type``)."""
    schema = channel.schema()
    if schema is None:
        raise UnknownType(f'{channel.topic} has no schema')
    package, kind, name = schema.name.split('/')
    return getattr(importlib.import_module(f'{package}.{kind}'), name)


def _service_schema(name: str, request: type, response: type) -> Any:
    """Return a JSON service schema whose request and response are those ROS types' schemas."""
    def message(cls: type, part: str) -> Any:
        schema = foxglove.Schema(name=f'{name}_{part}', encoding='jsonschema',
                                 data=json.dumps(json_schema(cls, f'{name}_{part}')).encode())
        return foxglove.MessageSchema(encoding='json', schema=schema)
    return foxglove.ServiceSchema(name, request=message(request, 'Request'),
                                  response=message(response, 'Response'))


def _unbound(name: str, address: str, port: int, error: OSError) -> InvalidParameters:
    """Return the start-up refusal of a port that cannot be bound (one FATAL line, exit 1)."""
    return InvalidParameters(
        f'view_node: {name} {port} on {address}: {error.strerror or error}; another view '
        '(wirefish view, wirefish up --view) may hold it: give it another port (wirefish '
        'view --port/--http-port, or 0 for any free one)')


def _json_safe(value: Any) -> Any:
    """Return ``value`` with every non-finite float (NaN, inf) replaced by None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    return value


def _answer(success: bool, message: str) -> bytes:
    return json.dumps({'success': success, 'message': message}).encode()


def main(args: list[str] | None = None) -> None:
    """Run the view node until shutdown."""
    run_node(ViewNode, args)
