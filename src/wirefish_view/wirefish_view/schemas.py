# SPDX-License-Identifier: Apache-2.0
"""
The ``ros2msg`` schemas of the graph's message types, for Foxglove channels (pure but for files).

A ros2msg schema is the type's .msg text followed by the .msg text of every type it names,
each after a line of 80 ``=`` and ``MSG: pkg/Type`` (the concatenated form ros2 bag and
Foxglove use). Definitions come from the installed share/<pkg>/msg/<Type>.msg.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
import re

from wirefish_view.errors import UnknownType

SEPARATOR = '=' * 80
PRIMITIVES = {'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16',
              'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring'}
# A field's type without its array or bound suffix: 'float64[2] x', 'string<=10 name'.
_FIELD_TYPE = re.compile(r'^\s*([A-Za-z][A-Za-z0-9_/]*)')


def _share_file(package: str, name: str) -> Path:
    from ament_index_python.packages import (get_package_share_directory,
                                             PackageNotFoundError)
    try:
        return Path(get_package_share_directory(package), 'msg', f'{name}.msg')
    except PackageNotFoundError as error:
        raise UnknownType(f'no package {package!r} for {package}/msg/{name}') from error


def split_type(type_name: str) -> tuple[str, str]:
    """Return (package, name) of ``pkg/msg/Type`` or ``pkg/Type``; raise UnknownType else."""
    parts = type_name.split('/')
    if len(parts) == 3 and parts[1] == 'msg':
        return parts[0], parts[2]
    if len(parts) == 2:
        return parts[0], parts[1]
    raise UnknownType(f'not a message type: {type_name!r}')


def referenced_types(text: str, package: str) -> list[str]:
    """Return the ``pkg/Type`` names the fields of a .msg ``text`` use, in order, once each."""
    found: list[str] = []
    for line in text.splitlines():
        line = line.split('#', 1)[0].strip()
        match = _FIELD_TYPE.match(line)
        if not line or match is None:
            continue
        base = match.group(1)
        if base in PRIMITIVES:  # constants are primitives too
            continue
        if base == 'Header':
            base = 'std_msgs/Header'
        elif '/' not in base:
            base = f'{package}/{base}'
        if base not in found:
            found.append(base)
    return found


def ros2msg_schema(type_name: str,
                   read: Callable[[str, str], str] | None = None) -> str:
    """Return the ros2msg schema of ``type_name`` (``pkg/msg/Type``) with every dependency."""
    read = read or (lambda package, name: _share_file(package, name).read_text())
    package, name = split_type(type_name)
    try:
        root = read(package, name)
    except OSError as error:
        raise UnknownType(f'no definition of {type_name}') from error
    parts = [root.rstrip('\n')]
    done: set[str] = {f'{package}/{name}'}
    todo = referenced_types(root, package)
    while todo:
        dependency = todo.pop(0)
        if dependency in done:
            continue
        done.add(dependency)
        dep_package, dep_name = split_type(dependency)
        try:
            text = read(dep_package, dep_name)
        except OSError as error:
            raise UnknownType(f'no definition of {dependency} (used by {type_name})') from error
        parts.append(f'{SEPARATOR}\nMSG: {dependency}\n{text.rstrip(chr(10))}')
        todo.extend(t for t in referenced_types(text, dep_package) if t not in done)
    return '\n'.join(parts) + '\n'
