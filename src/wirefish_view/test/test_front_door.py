# SPDX-License-Identifier: Apache-2.0
"""The front door's pure parts: which subprotocol a handshake gets, and the status rate limit."""

import json

from websockets.datastructures import Headers
from wirefish_view.errors import Refusal
from wirefish_view.front_door import (chosen_subprotocol, offered_subprotocols, status_frame,
                                      StatusLimiter, SUBPROTOCOLS)


def test_either_name_is_accepted_in_the_clients_order():
    assert chosen_subprotocol(['foxglove.websocket.v1']) == 'foxglove.websocket.v1'
    assert chosen_subprotocol(['foxglove.sdk.v1']) == 'foxglove.sdk.v1'
    assert chosen_subprotocol(['x.v2', 'foxglove.websocket.v1', 'foxglove.sdk.v1']) == (
        'foxglove.websocket.v1')
    assert set(SUBPROTOCOLS) == {'foxglove.sdk.v1', 'foxglove.websocket.v1'}


def test_a_handshake_offering_neither_gets_none():
    assert chosen_subprotocol([]) is None
    assert chosen_subprotocol(['foxglove.websocket.v2', 'foxglove.sdk.v1.1']) is None


def test_offered_names_are_read_from_every_header_line():
    headers = Headers([('Sec-WebSocket-Protocol', 'a, b'), ('Sec-WebSocket-Protocol', 'c')])
    assert offered_subprotocols(headers) == ['a', 'b', 'c']
    assert offered_subprotocols(Headers()) == []


def test_one_status_per_period_per_key_with_the_count_held_back():
    limiter = StatusLimiter(period_s=1.0)
    assert limiter.allow(Refusal.UNADVERTISED, 0.0) == 0
    assert [limiter.allow(Refusal.UNADVERTISED, 0.1 * i) for i in range(1, 10)] == [None] * 9
    assert limiter.allow(Refusal.CHANNEL, 0.5) == 0  # another kind has its own allowance
    assert limiter.allow(Refusal.UNADVERTISED, 1.0) == 9
    assert limiter.allow(Refusal.UNADVERTISED, 1.5) is None


def test_a_status_is_a_warning_with_an_id_of_its_client_and_kind():
    frame = json.loads(status_frame('refused', Refusal.OUT_OF_LIMITS, 7))
    assert frame == {'op': 'status', 'level': 1, 'message': 'refused',
                     'id': 'refused/7/out of limits'}
