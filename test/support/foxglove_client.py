# SPDX-License-Identifier: Apache-2.0
"""
A Foxglove WebSocket client of the tests' own (protocol ``foxglove.sdk.v1``), over `websockets`.

Text frames are JSON operations (serverInfo, advertise, status, advertiseServices ...); binary
frames from the server start with an opcode: 1 message data (subscription u32, log time u64,
payload), 3 a service call's response (service u32, call u32, encoding length u32, encoding,
payload). A reader thread sorts what arrives; the test reads it under ``lock``.
"""

from __future__ import annotations

import json
import socket
import struct
import threading
import time

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

SUBPROTOCOL = 'foxglove.sdk.v1'


class FoxgloveClient:
    """One connection: the channels advertised, the messages of each subscription, statuses."""

    def __init__(self, url: str) -> None:
        self.ws = connect(url, subprotocols=[SUBPROTOCOL], open_timeout=10, max_size=None)
        self.lock = threading.Lock()
        self.server_info: dict | None = None
        self.channels: dict[int, dict] = {}  # id -> advertised channel
        self.services: dict[str, dict] = {}  # name -> advertised service
        self.statuses: list[dict] = []
        self.messages: dict[int, list[tuple[int, bytes]]] = {}  # subscription -> (ns, payload)
        self.responses: dict[int, bytes] = {}  # call id -> payload
        self.closed = False
        self._next_id = 1
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        try:
            for frame in self.ws:
                if isinstance(frame, str):
                    self._on_text(json.loads(frame))
                elif frame[0] == 1:
                    subscription, log_time = struct.unpack_from('<IQ', frame, 1)
                    with self.lock:
                        self.messages.setdefault(subscription, []).append(
                            (log_time, bytes(frame[13:])))
                elif frame[0] == 3:
                    _, call, length = struct.unpack_from('<III', frame, 1)
                    with self.lock:
                        self.responses[call] = bytes(frame[13 + length:])
        except ConnectionClosed:
            pass
        self.closed = True

    def _on_text(self, op: dict) -> None:
        with self.lock:
            if op['op'] == 'serverInfo':
                self.server_info = op
            elif op['op'] == 'advertise':
                self.channels.update({c['id']: c for c in op['channels']})
            elif op['op'] == 'unadvertise':
                for channel_id in op['channelIds']:
                    self.channels.pop(channel_id, None)
            elif op['op'] == 'advertiseServices':
                self.services.update({s['name']: s for s in op['services']})
            elif op['op'] == 'status':
                self.statuses.append(op)

    def wait(self, predicate, timeout_s: float) -> bool:
        """Return once ``predicate()`` holds (True) or after ``timeout_s`` (its value then)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self.lock:
                if predicate():
                    return True
            time.sleep(0.05)
        with self.lock:
            return predicate()

    def channel_of(self, topic: str) -> dict | None:
        """Return the advertised channel of ``topic``, or None."""
        return next((c for c in self.channels.values() if c['topic'] == topic), None)

    def subscribe(self, channel_id: int) -> int:
        """Subscribe to a channel; return the subscription id."""
        subscription = self._take_id()
        self.ws.send(json.dumps({'op': 'subscribe',
                                 'subscriptions': [{'id': subscription,
                                                    'channelId': channel_id}]}))
        return subscription

    def advertise(self, topic: str, encoding: str, schema_name: str) -> int:
        """Advertise a client channel; return its id."""
        channel = self._take_id()
        self.ws.send(json.dumps({'op': 'advertise', 'channels': [
            {'id': channel, 'topic': topic, 'encoding': encoding, 'schemaName': schema_name}]}))
        return channel

    def publish(self, channel: int, payload: bytes) -> None:
        """Send one message on a client channel (opcode 1)."""
        self.ws.send(struct.pack('<BI', 1, channel) + payload)

    def call(self, service: str, payload: bytes, encoding: str = 'json') -> int:
        """Call an advertised service (opcode 2); return the call id."""
        call = self._take_id()
        service_id = self.services[service]['id']
        self.ws.send(struct.pack('<BIII', 2, service_id, call, len(encoding))
                     + encoding.encode() + payload)
        return call

    def _take_id(self) -> int:
        self._next_id += 1
        return self._next_id

    def close(self) -> None:
        """Close the connection and wait for the reader."""
        self.ws.close()
        self._reader.join(5.0)


def free_port() -> int:
    """Return a TCP port that nothing on this machine listens on now."""
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]
