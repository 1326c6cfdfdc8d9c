# SPDX-License-Identifier: Apache-2.0
"""
`wirefish param list|get|set`: the ``ros2 param`` verbs for machines without ros2cli.

``list NODE`` prints the node's parameters, ``get NODE NAME`` one value (as ``ros2 param get``
words it), ``set NODE NAME VALUE`` sets one, VALUE read as YAML as ``ros2 param set`` does
(``0.3`` a double, ``true`` a bool, ``3`` an integer). A refused value prints the node's reason
and exits 1. A relative node name is taken in ``--namespace`` (default /wirefish):
``wirefish param set cpg_node amplitude_1 0.3``.
"""

from __future__ import annotations

import argparse
import difflib
import enum
import sys
import time

from wirefish_cli.ros_session import ros_session, RosSession

SERVICE_WAIT_S = 10.0  # how long to wait for the node's parameter services
# How long the graph is looked at before a node it does not show is said missing (a running
# node was discovered within 0 to 2.3 s on the loaded 2-core machine).
NODE_DISCOVERY_S = 3.0
DOUBLE = 3
EXAMPLES = {1: 'true or false', 2: 'a whole number such as 3', 3: 'a number such as 0.3',
            4: 'text'}
# What `ros2 param get` says before a value, by rcl_interfaces/ParameterType.
TYPE_WORDS = {1: 'Boolean', 2: 'Integer', 3: 'Double', 4: 'String', 5: 'Byte array',
              6: 'Boolean array', 7: 'Integer array', 8: 'Double array', 9: 'String array'}
_VALUE_FIELDS = {1: 'bool_value', 2: 'integer_value', 3: 'double_value', 4: 'string_value',
                 5: 'byte_array_value', 6: 'bool_array_value', 7: 'integer_array_value',
                 8: 'double_array_value', 9: 'string_array_value'}


class ParamVerb(enum.StrEnum):
    """The verbs of `wirefish param`, as `ros2 param` names them."""

    LIST = 'list'
    GET = 'get'
    SET = 'set'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare `wirefish param list | get | set` and their arguments."""
    from wirefish_bringup.graph import DEFAULT_NAMESPACE

    verbs = parser.add_subparsers(dest='verb', required=True, metavar='VERB')
    helps = {ParamVerb.LIST: "a node's parameters", ParamVerb.GET: "one parameter's value",
             ParamVerb.SET: 'set one parameter (the node may refuse it, with its reason)'}
    listing, get, put = (verbs.add_parser(verb.value, help=text, description=text)
                         for verb, text in helps.items())
    for sub in (listing, get, put):
        sub.add_argument('node', help='node name (relative: in --namespace), e.g. cpg_node')
        sub.add_argument('--namespace', default=DEFAULT_NAMESPACE,
                         help='namespace of a relative node name (default %(default)s)')
    for sub in (get, put):
        sub.add_argument('name', help='parameter name')
    put.add_argument('value', help='the value, read as YAML (0.3, true, 3, text)')


def node_name(node: str, namespace: str) -> str:
    """Return ``node`` as a fully qualified name (a relative one in ``namespace``)."""
    return node if node.startswith('/') else f'{namespace.rstrip("/")}/{node}'


def value_text(value) -> str:
    """Return a rcl_interfaces/ParameterValue as `ros2 param get` prints it."""
    if value.type == 0:
        return 'Parameter not set.'
    shown = getattr(value, _VALUE_FIELDS[value.type])
    if hasattr(shown, 'tolist'):
        shown = shown.tolist()
    return f'{TYPE_WORDS[value.type]} value is: {list(shown) if value.type >= 5 else shown}'


def parameter_message(name: str, text: str, declared_type: int | None = None):
    """
    Return a rcl_interfaces/Parameter of ``text`` read as YAML (as ros2 param set reads).

    With the parameter's current type, an integer is given as a double where the parameter is
    a double (``99`` -> 99.0); any other mismatch raises ValueError saying what to type.
    """
    import yaml
    from rclpy.parameter import Parameter

    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        value = text
    if value is None or isinstance(value, dict):
        value = text
    if declared_type == DOUBLE and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    message = Parameter(name, value=value).to_parameter_msg()
    if declared_type is not None and declared_type != 0 and \
            message.value.type != declared_type:
        raise ValueError(f'{name} is a {TYPE_WORDS[declared_type]}, {text!r} is a '
                         f'{TYPE_WORDS.get(message.value.type, "value")}: give '
                         f'{EXAMPLES.get(declared_type, "a value of that type")}')
    return message


def run(args: argparse.Namespace) -> int:
    """Run `wirefish param ...`; return the exit code."""
    target = node_name(args.node, args.namespace)
    with ros_session('wirefish_param') as session:
        return _run(session, args, target)


def _run(session: RosSession, args: argparse.Namespace, target: str) -> int:
    from rcl_interfaces.srv import GetParameters, ListParameters, SetParameters

    missing = _wait_for_node(session, target)
    if missing is not None:
        print(f'wirefish param {args.verb}: {missing}', file=sys.stderr)
        return 1
    if args.verb == ParamVerb.LIST:
        response = _call(session, target, ListParameters, 'list_parameters',
                         ListParameters.Request())
        if isinstance(response, str):
            print(f'wirefish param list: {response}', file=sys.stderr)
            return 1
        for name in sorted(response.result.names):
            print(f'  {name}')
        return 0
    current = _call(session, target, GetParameters, 'get_parameters',
                    GetParameters.Request(names=[args.name]))
    if isinstance(current, str):
        print(f'wirefish param {args.verb}: {current}', file=sys.stderr)
        return 1
    if not current.values or current.values[0].type == 0:
        listed = _call(session, target, ListParameters, 'list_parameters',
                       ListParameters.Request())
        names = [] if isinstance(listed, str) else list(listed.result.names)
        print(f'wirefish param {args.verb}: {unknown_name_text(target, args.name, names)}',
              file=sys.stderr)
        return 1
    if args.verb == ParamVerb.GET:
        print(value_text(current.values[0]))
        return 0
    try:
        parameter = parameter_message(args.name, args.value, current.values[0].type)
    except (TypeError, ValueError) as error:
        print(f'wirefish param set: {error}', file=sys.stderr)
        return 2
    response = _call(session, target, SetParameters, 'set_parameters',
                     SetParameters.Request(parameters=[parameter]))
    if isinstance(response, str):
        print(f'wirefish param set: {response}', file=sys.stderr)
        return 1
    result = response.results[0]
    if result.successful:
        print('Set parameter successful')
        return 0
    print(f'Setting parameter failed: {result.reason}', file=sys.stderr)
    return 1


def _wait_for_node(session: RosSession, target: str) -> str | None:
    """
    Wait until ``target`` is on the graph; return why it is not there, or None.

    Once the graph shows other nodes for NODE_DISCOVERY_S, a missing node is missing (with the
    closest names); with nothing discovered at all the wait goes on to SERVICE_WAIT_S.
    """
    node = session.node
    started = time.monotonic()
    while True:
        names = [f'{ns.rstrip("/")}/{name}' for name, ns in node.get_node_names_and_namespaces()]
        if target in names:
            return None
        waited = time.monotonic() - started
        others = [name for name in names if name != node.get_fully_qualified_name()]
        if (others and waited >= NODE_DISCOVERY_S) or waited >= SERVICE_WAIT_S:
            return missing_node_text(target, others, waited)
        session.spin_once(0.1)


def missing_node_text(target: str, others: list[str], waited_s: float) -> str:
    """Return the one line of a node that is not on the graph, with the closest names."""
    close = difflib.get_close_matches(target, others, n=3)
    if close:
        return f'no node {target}; did you mean {" or ".join(close)}?'
    if others:
        return f'no node {target} (the nodes: {", ".join(sorted(others))})'
    return f'no node {target}: no node at all on this ROS domain within {waited_s:.0f} s'


def unknown_name_text(target: str, name: str, names: list[str]) -> str:
    """Return the one line of a parameter name the node does not have, with the closest."""
    close = difflib.get_close_matches(name, names, n=3)
    hint = (f'; did you mean {" or ".join(close)}?' if close
            else f' (wirefish param list {target} shows its parameters)')
    return f'{target} has no parameter {name}{hint}'


def _call(session: RosSession, target: str, kind, service: str, request):
    """Call one of the node's parameter services; return its response, or why there is none."""
    client = session.node.create_client(kind, f'{target}/{service}')
    if not client.wait_for_service(timeout_sec=SERVICE_WAIT_S):
        return f'{target} has no {service} service (within {SERVICE_WAIT_S:g} s)'
    future = client.call_async(request)
    if not session.spin_until(future.done, SERVICE_WAIT_S) or future.result() is None:
        return f'{target} did not answer'
    return future.result()
