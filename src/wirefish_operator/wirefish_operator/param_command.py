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
import enum
import sys

SERVICE_WAIT_S = 10.0  # how long to wait for the node's parameter services
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


def parameter_message(name: str, text: str):
    """Return a rcl_interfaces/Parameter of ``text`` read as YAML (as ros2 param set reads)."""
    import yaml
    from rclpy.parameter import Parameter

    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        value = text
    if value is None or isinstance(value, dict):
        value = text
    return Parameter(name, value=value).to_parameter_msg()


def run(args: argparse.Namespace) -> int:
    """Run `wirefish param ...`; return the exit code."""
    import rclpy
    from rcl_interfaces.srv import GetParameters, ListParameters, SetParameters
    from rclpy.signals import SignalHandlerOptions

    target = node_name(args.node, args.namespace)
    kinds = {ParamVerb.LIST: (ListParameters, 'list_parameters'),
             ParamVerb.GET: (GetParameters, 'get_parameters'),
             ParamVerb.SET: (SetParameters, 'set_parameters')}
    kind, service = kinds[args.verb]
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node('wirefish_param', start_parameter_services=False)
    try:
        client = node.create_client(kind, f'{target}/{service}')
        if not client.wait_for_service(timeout_sec=SERVICE_WAIT_S):
            print(f'wirefish param {args.verb}: no node {target} (its {service} service did not '
                  f'answer within {SERVICE_WAIT_S:g} s)', file=sys.stderr)
            return 1
        request = kind.Request()
        if args.verb == ParamVerb.GET:
            request.names = [args.name]
        elif args.verb == ParamVerb.SET:
            try:
                request.parameters = [parameter_message(args.name, args.value)]
            except (TypeError, ValueError) as error:
                print(f'wirefish param set: {args.value!r} is no parameter value: {error}',
                      file=sys.stderr)
                return 2
        future = client.call_async(request)
        rclpy.spin_until_future_complete(node, future, timeout_sec=SERVICE_WAIT_S)
        if not future.done() or future.result() is None:
            print(f'wirefish param {args.verb}: {target} did not answer', file=sys.stderr)
            return 1
        return _show(args, future.result())
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def _show(args: argparse.Namespace, response) -> int:
    if args.verb == ParamVerb.LIST:
        for name in sorted(response.result.names):
            print(f'  {name}')
        return 0
    if args.verb == ParamVerb.GET:
        if not response.values or response.values[0].type == 0:
            print(f'wirefish param get: {args.node} has no parameter {args.name}',
                  file=sys.stderr)
            return 1
        print(value_text(response.values[0]))
        return 0
    result = response.results[0]
    if result.successful:
        print('Set parameter successful')
        return 0
    print(f'Setting parameter failed: {result.reason}', file=sys.stderr)
    return 1
