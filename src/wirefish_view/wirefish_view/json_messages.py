# SPDX-License-Identifier: Apache-2.0
"""
ROS message types as JSON: their JSON Schema, and a message filled strictly from JSON.

The view's services (``start``, ``stop``, ``follow_commands``: std_srvs/Trigger; ``retune_gait``:
the RetuneGait action's goal, answered as a Trigger response) take and give JSON. Their schemas
are generated here from the rosidl classes (``get_fields_and_field_types``), so a generic
service panel shows the real fields; the same field table checks a request: JSON that does not
parse, a field the type does not have, or a value of the wrong type or out of its integer range
raises ``RefusedInput`` with the reason, and nothing is sent. Omitted fields keep the type's
defaults (``use_library`` true in the goal).
"""

from __future__ import annotations

import importlib
import json
import math
import re
from typing import Any

from wirefish_view.errors import Refusal, RefusedInput

_INTEGERS = {f'{sign}int{bits}': ((0, 2**bits - 1) if sign else (-2**(bits - 1),
                                                                 2**(bits - 1) - 1))
             for sign in ('', 'u') for bits in (8, 16, 32, 64)}
_INTEGERS.update({'octet': (0, 255), 'char': (0, 255), 'byte': (0, 255)})
_NUMBERS = ('float', 'double', 'long double')
_STRINGS = ('string', 'wstring')
_SEQUENCE = re.compile(r'^sequence<(?P<item>[^,>]+)(?:, (?P<bound>\d+))?>$')
_ARRAY = re.compile(r'^(?P<item>.+)\[(?P<size>\d+)\]$')
_BOUNDED_STRING = re.compile(r'^(?P<kind>w?string)<=(?P<bound>\d+)$')


def message_class(type_name: str) -> type:
    """Return the class of ``pkg/Type``, ``pkg/msg/Type`` (a nested field's type name)."""
    parts = type_name.split('/')
    package, name = parts[0], parts[-1]
    kind = parts[1] if len(parts) == 3 else 'msg'
    return getattr(importlib.import_module(f'{package}.{kind}'), name)


def _items(kind: str) -> tuple[str, int | None, bool] | None:
    """Return (item type, size, exact) of an array or sequence type, None for any other."""
    array = _ARRAY.match(kind)
    if array:
        return array['item'], int(array['size']), True
    sequence = _SEQUENCE.match(kind)
    if sequence:
        return sequence['item'], int(sequence['bound']) if sequence['bound'] else None, False
    return None


def _field_schema(kind: str) -> dict:
    items = _items(kind)
    if items is not None:
        item, size, exact = items
        schema: dict = {'type': 'array', 'items': _field_schema(item)}
        if size is not None:
            schema['maxItems'] = size
            if exact:
                schema['minItems'] = size
        return schema
    bounded = _BOUNDED_STRING.match(kind)
    if bounded:
        return {'type': 'string', 'maxLength': int(bounded['bound'])}
    if kind == 'boolean':
        return {'type': 'boolean'}
    if kind in _INTEGERS:
        low, high = _INTEGERS[kind]
        return {'type': 'integer', 'minimum': low, 'maximum': high}
    if kind in _NUMBERS:
        return {'type': 'number'}
    if kind in _STRINGS:
        return {'type': 'string'}
    return json_schema(message_class(kind), kind)


def json_schema(cls: Any, title: str | None = None) -> dict:
    """Return the JSON Schema of a rosidl message class (nested types inlined)."""
    return {'type': 'object', 'title': title or f'{cls.__module__.split(".")[0]}/{cls.__name__}',
            'properties': {name: _field_schema(kind)
                           for name, kind in cls.get_fields_and_field_types().items()},
            'additionalProperties': False}


def _value(kind: str, value: Any, where: str) -> Any:
    items = _items(kind)
    if items is not None:
        item, size, exact = items
        if not isinstance(value, list):
            raise RefusedInput(f'{where} must be an array, got {json.dumps(value)}')
        if size is not None and (len(value) != size if exact else len(value) > size):
            raise RefusedInput(f'{where} must have {"" if exact else "at most "}{size} items, '
                               f'got {len(value)}')
        return [_value(item, v, f'{where}[{i}]') for i, v in enumerate(value)]
    if kind == 'boolean':
        if not isinstance(value, bool):
            raise RefusedInput(f'{where} must be true or false, got {json.dumps(value)}')
        return value
    if kind in _INTEGERS:
        low, high = _INTEGERS[kind]
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise RefusedInput(f'{where} must be a whole number in [{low}, {high}], got '
                               f'{json.dumps(value)}')
        return value
    if kind in _NUMBERS:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(
                value):
            raise RefusedInput(f'{where} must be a finite number, got {json.dumps(value)}')
        return float(value)
    if kind in _STRINGS or _BOUNDED_STRING.match(kind):
        if not isinstance(value, str):
            raise RefusedInput(f'{where} must be a string, got {json.dumps(value)}')
        return value
    return fill(message_class(kind)(), value, where)


def fill(message: Any, fields: Any, where: str = 'request') -> Any:
    """Set ``message``'s fields from a JSON object; raise ``RefusedInput`` for a bad one."""
    if not isinstance(fields, dict):
        raise RefusedInput(f'{where} must be a JSON object, got {json.dumps(fields)}')
    kinds = type(message).get_fields_and_field_types()
    unknown = sorted(set(fields) - set(kinds))
    if unknown:
        raise RefusedInput(f'{where}: no field {", ".join(unknown)} (fields: '
                           f'{", ".join(kinds) or "none"})')
    for name, value in fields.items():
        setattr(message, name, _value(kinds[name], value, f'{where}.{name}'
                                      if where != 'request' else name))
    return message


def from_json(cls: type, payload: bytes) -> Any:
    """Return a ``cls`` message from a JSON request (empty: all defaults)."""
    text = bytes(payload).decode('utf-8', errors='replace').strip()
    try:
        fields = json.loads(text) if text else {}
    except ValueError as error:
        raise RefusedInput(f'not JSON ({error}): {text[:40]!r}', Refusal.MALFORMED) from error
    return fill(cls(), fields)
