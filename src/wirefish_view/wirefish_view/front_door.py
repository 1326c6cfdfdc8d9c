# SPDX-License-Identifier: Apache-2.0
"""
The view's WebSocket front door: either Foxglove subprotocol name, client publishing, statuses.

foxglove-sdk's server accepts only the subprotocol ``foxglove.sdk.v1``; the ws-protocol
specification, ``@foxglove/ws-protocol``'s ``FoxgloveClient`` and older Lichtblick releases offer
``foxglove.websocket.v1``, the same protocol under its first name. The front door listens on the
view's port, accepts a handshake offering either name (``SUBPROTOCOLS``; a handshake offering
neither is refused with HTTP 400, and the offered and supported names are logged), and relays
each client to the sdk's server on a loopback port of its own, as ``foxglove.sdk.v1``.

Client publishing is answered here, per client, instead of by the sdk (whose statuses go to
every client): a client's ``advertise`` and ``unadvertise`` and its binary message data (opcode
1: u8 opcode, u32 LE channel id, payload) are checked by the node's ``ClientPublish`` and never
reach the sdk. A refusal's status goes only to the client that caused it, at most one per
``STATUS_PERIOD_S`` per client and kind of refusal (``Refusal``), with the count refused since
the last one; the log gets the same, at the same rate. Everything else is relayed as it is.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from http import HTTPStatus
import itertools
import json
import struct
import threading
import time
from typing import Protocol

from websockets.asyncio.client import connect
from websockets.asyncio.server import serve, ServerConnection
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response
from websockets.typing import Subprotocol
from wirefish_view.errors import Refusal, RefusedInput

SUBPROTOCOLS = (Subprotocol('foxglove.sdk.v1'), Subprotocol('foxglove.websocket.v1'))
UPSTREAM_SUBPROTOCOL = Subprotocol('foxglove.sdk.v1')
STATUS_PERIOD_S = 1.0
CLIENT_MESSAGE_DATA = 0x01
WARNING = 1  # the protocol's status levels: 0 info, 1 warning, 2 error
_CHANNEL_HEADER = struct.Struct('<BI')


class ClientPublish(Protocol):
    """What the node decides about a client's channels and messages."""

    def check_channel(self, topic: str, encoding: str, schema_name: str) -> None:
        """Raise ``RefusedInput`` unless a client may publish on this channel."""

    def publish(self, encoding: str, data: bytes) -> None:
        """Publish a message of an accepted channel; raise ``RefusedInput`` if it is refused."""


def offered_subprotocols(headers: Headers) -> list[str]:
    """Return the subprotocol names a handshake offers, in its order."""
    return [name.strip() for value in headers.get_all('Sec-WebSocket-Protocol')
            for name in value.split(',') if name.strip()]


def chosen_subprotocol(offered: Sequence[str]) -> Subprotocol | None:
    """Return the first offered name the view speaks, or None."""
    return next((Subprotocol(name) for name in offered if name in SUBPROTOCOLS), None)


@dataclass
class StatusLimiter:
    """At most one status per ``period_s`` per key; counts what it held back meanwhile."""

    period_s: float = STATUS_PERIOD_S
    _last: dict[object, float] = field(default_factory=dict)
    _held: dict[object, int] = field(default_factory=dict)

    def allow(self, key: object, now: float) -> int | None:
        """Return the count held back since the last one if a status may go now, else None."""
        if now - self._last.get(key, -float('inf')) < self.period_s:
            self._held[key] = self._held.get(key, 0) + 1
            return None
        self._last[key] = now
        return self._held.pop(key, 0)


def status_frame(message: str, kind: Refusal, client_id: int) -> str:
    """Return the ws-protocol status message of a refusal (a warning, id per client and kind)."""
    return json.dumps({'op': 'status', 'level': WARNING, 'message': message,
                       'id': f'refused/{client_id}/{kind.value}'})


@dataclass
class _Client:
    number: int
    connection: ServerConnection
    channels: dict[int, str] = field(default_factory=dict)  # accepted channel id -> encoding
    limiter: StatusLimiter = field(default_factory=StatusLimiter)


class FrontDoor:
    """The WebSocket server of the view's port, relaying to the sdk's server on ``upstream``."""

    def __init__(self, address: str, port: int, upstream_port: int, publisher: ClientPublish,
                 log: Callable[[str], None]) -> None:
        """Bind ``address``:``port`` (0: a free port) and serve in a thread of its own."""
        self._upstream = f'ws://127.0.0.1:{upstream_port}'
        self._publisher, self._log = publisher, log
        self._ids = itertools.count(1)
        self._loop = asyncio.new_event_loop()
        self._stopped: asyncio.Event | None = None
        bound: list[int | BaseException] = []
        ready = threading.Event()
        self._thread = threading.Thread(
            target=self._run, args=(address, port, bound, ready), name='view-front-door',
            daemon=True)
        self._thread.start()
        ready.wait()
        if isinstance(bound[0], BaseException):
            raise bound[0]
        self.port = bound[0]

    # --- the thread ------------------------------------------------------------------------
    def _run(self, address: str, port: int, bound: list, ready: threading.Event) -> None:
        asyncio.set_event_loop(self._loop)
        try:
            self._loop.run_until_complete(self._serve(address, port, bound, ready))
        except BaseException as error:  # a bind that failed: the constructor raises it
            if not ready.is_set():
                bound.append(error)
                ready.set()
        finally:
            self._loop.close()

    async def _serve(self, address: str, port: int, bound: list, ready: threading.Event
                     ) -> None:
        self._stopped = asyncio.Event()
        async with serve(self._relay, address, port, subprotocols=list(SUBPROTOCOLS),
                         select_subprotocol=lambda _c, offered: chosen_subprotocol(offered),
                         process_request=self._check_handshake, compression=None,
                         server_header=None) as server:
            bound.append(next(iter(server.sockets)).getsockname()[1])
            ready.set()
            await self._stopped.wait()

    def stop(self) -> None:
        """Close every connection and the port; join the thread."""
        if self._stopped is not None and self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._stopped.set)
        self._thread.join(5.0)

    # --- one client ------------------------------------------------------------------------
    def _check_handshake(self, connection: ServerConnection, request: Request
                         ) -> Response | None:
        offered = offered_subprotocols(request.headers)
        if chosen_subprotocol(offered) is not None or 'Upgrade' not in request.headers:
            return None
        reason = (f'WebSocket handshake refused: offered subprotocols {offered or "none"}, '
                  f'supported {list(SUBPROTOCOLS)}')
        self._log(reason)
        return connection.respond(HTTPStatus.BAD_REQUEST, reason + '\n')

    async def _relay(self, downstream: ServerConnection) -> None:
        client = _Client(next(self._ids), downstream)
        try:
            upstream = await connect(self._upstream, subprotocols=[UPSTREAM_SUBPROTOCOL],
                                     compression=None, max_size=None, ping_interval=None)
        except (OSError, ConnectionClosed) as error:
            self._log(f'client {client.number}: the Foxglove server is not reachable ({error})')
            return
        async with upstream:
            tasks = [asyncio.ensure_future(self._down(upstream, downstream)),
                     asyncio.ensure_future(self._up(client, upstream))]
            await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)

    async def _down(self, upstream, downstream: ServerConnection) -> None:
        try:
            async for message in upstream:
                await downstream.send(message)
        except ConnectionClosed:
            pass

    async def _up(self, client: _Client, upstream) -> None:
        try:
            async for message in client.connection:
                if not await self._answered_here(client, message):
                    await upstream.send(message)
        except ConnectionClosed:
            pass

    async def _answered_here(self, client: _Client, message: str | bytes) -> bool:
        """Handle a client-publish message; return False for what the sdk answers."""
        try:
            if isinstance(message, bytes):
                if not message or message[0] != CLIENT_MESSAGE_DATA:
                    return False
                self._on_message_data(client, message)
                return True
            request = json.loads(message)
            op = request.get('op') if isinstance(request, dict) else None
            if op == 'advertise':
                self._on_advertise(client, request.get('channels'))
                return True
            if op == 'unadvertise':
                for channel_id in request.get('channelIds') or ():
                    client.channels.pop(channel_id, None)
                return True
        except RefusedInput as error:
            await self._refuse(client, error)
            return True
        except ValueError:
            pass  # not JSON: the sdk's answer (a status to this client) is the right one
        return False

    def _on_advertise(self, client: _Client, channels: object) -> None:
        if not isinstance(channels, list):
            raise RefusedInput(f'client {client.number}: advertise without a list of channels')
        for channel in channels:
            try:
                channel_id, topic = channel['id'], channel['topic']
                encoding, schema_name = channel['encoding'], channel['schemaName']
            except (KeyError, TypeError) as error:
                raise RefusedInput(f'client {client.number}: advertised channel without {error}'
                                   ) from error
            self._publisher.check_channel(topic, encoding, schema_name)
            client.channels[int(channel_id)] = encoding

    def _on_message_data(self, client: _Client, message: bytes) -> None:
        if len(message) < _CHANNEL_HEADER.size:
            raise RefusedInput(f'client {client.number}: message data of {len(message)} bytes')
        _, channel_id = _CHANNEL_HEADER.unpack_from(message)
        encoding = client.channels.get(channel_id)
        if encoding is None:
            raise RefusedInput(f'client {client.number}: message on channel {channel_id} refused: '
                               'only an accepted cmd_vel channel is', Refusal.UNADVERTISED)
        self._publisher.publish(encoding, message[_CHANNEL_HEADER.size:])

    async def _refuse(self, client: _Client, error: RefusedInput) -> None:
        held = client.limiter.allow(error.kind, time.monotonic())
        if held is None:
            return
        message = str(error) + (f' ({held} more refused since the last status)' if held else '')
        self._log(message)
        try:
            await client.connection.send(status_frame(message, error.kind, client.number))
        except ConnectionClosed:
            pass
