# SPDX-License-Identifier: Apache-2.0
"""The node registry: the one description of a fish's processes, and their restart policy."""

import ast
from pathlib import Path

import pytest
from wirefish_bridge.bridge_node_parameters import TABLE as BRIDGE_TABLE
from wirefish_bringup.graph import (combined_policy, composable_entries, entries, expected_rates,
                                    fish_graph, NODES, NodeSpec, RestartBudget, RestartPolicy,
                                    Role, sim_tty_link, validate_namespace)
from wirefish_cpg.cpg_node_parameters import TABLE as CPG_TABLE

LAUNCH_FILE = Path(__file__).resolve().parents[1] / 'launch' / 'wirefish.launch.py'


def test_the_virtual_fish_starts_first_and_the_bridge_opens_its_link():
    specs = fish_graph('/tank/fish_1', sim=True, params_file='p.yaml')
    assert [s.executable for s in specs] == [
        'fish_sim', 'bridge_node', 'cpg_node', 'kinematics_node', 'tf_node', 'planner_node',
        'tuner_node']
    link = str(sim_tty_link('/tank/fish_1'))
    assert specs[0].command_arguments()[:3] == ('--link', link, '--ros')
    assert specs[0].links == (Path(link),)
    assert f'port:={link}' in specs[1].command_arguments()
    for spec in specs:
        args = spec.command_arguments()
        assert '__ns:=/tank/fish_1' in args and f'__node:={spec.name}' in args
        assert args[args.index('--params-file') + 1] == 'p.yaml'


def test_a_real_fish_has_no_virtual_fish_and_the_bridge_opens_the_port():
    specs = fish_graph('/wirefish', sim=False, port='/dev/ttyUSB0')
    assert 'fish_sim' not in [s.executable for s in specs]
    assert 'port:=/dev/ttyUSB0' in specs[0].command_arguments()


def test_single_process_is_the_virtual_fish_and_one_process_of_every_node_class():
    specs = fish_graph('/wirefish', sim=True, single_process=True)
    assert [s.name for s in specs] == ['fish_sim', 'fish_nodes']
    assert specs[1].ros_nodes == tuple(e.name for e in composable_entries())
    assert (specs[1].package, specs[1].executable) == ('wirefish_launcher', 'compose')


def test_a_bag_adds_the_recorder_last_with_its_own_options_only():
    specs = fish_graph('/wirefish', sim=True, bag=Path('/tmp/b'))
    recorder = specs[-1]
    assert (recorder.package, recorder.executable) == ('wirefish_bag', 'recorder')
    assert recorder.command_arguments() == ('-o', '/tmp/b', '--namespace', '/wirefish',
                                            '--resume')  # a restart records on into the bag
    assert recorder.restart.respawn
    assert recorder.ros_nodes == ()  # its node is not in the namespace: not waited for


def test_start_order_does_not_depend_on_the_role():
    real = [s.name for s in fish_graph('/w', sim=False, port='/dev/ttyUSB0')]
    sim = [s.name for s in fish_graph('/w', sim=True)]
    assert sim[1:] == real


def test_every_registry_name_is_unique():
    names = [e.name for e in NODES]
    assert len(names) == len(set(names))


def test_every_node_class_names_a_module_and_a_class():
    for e in composable_entries():
        module, _, cls = e.node_class.partition(':')
        assert module.startswith(e.package + '.') and cls.isidentifier(), e.name


def test_servo_cmd_is_expected_at_the_rate_the_bridge_forwards_to_the_board():
    nominal, _ = expected_rates(sim=True)
    assert nominal['servo_cmd'] == CPG_TABLE.by_name['publish_rate_hz'].default
    assert nominal['servo_cmd'] == BRIDGE_TABLE.by_name['max_command_rate_hz'].default


def test_the_expected_rates_are_the_registry_streams():
    nominal, minimum = expected_rates(sim=True)
    assert nominal['sim/ground_truth'] == 50.0
    assert minimum['/diagnostics'] > 0.0
    assert 'sim/ground_truth' not in expected_rates(sim=False)[0]


def test_streams_are_only_fed_by_nodes_of_the_registry():
    names = {e.name for e in NODES}
    for e in NODES:
        assert set(e.fed_by) <= names, e.name


def test_a_plain_node_spec_passes_its_arguments_verbatim():
    spec = NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node', ('--ros-args', '-p', 'a:=1'))
    assert spec.command_arguments() == ('--ros-args', '-p', 'a:=1')
    assert not spec.restart.respawn


@pytest.mark.parametrize('sim, port, reason', [
    (False, None, 'needs its serial port'),
    (True, '/dev/ttyUSB0', 'choose sim or a port'),
])
def test_contradictory_targets_are_refused(sim, port, reason):
    with pytest.raises(ValueError, match=reason):
        fish_graph('/wirefish', sim=sim, port=port)


@pytest.mark.parametrize('given, normalised', [('wirefish', '/wirefish'), ('/a/b/', '/a/b'),
                                               ('/', '/')])
def test_namespaces_are_normalised(given, normalised):
    assert validate_namespace(given) == normalised


@pytest.mark.parametrize('empty', ['', '  '])
def test_an_empty_namespace_is_refused_not_taken_as_the_root(empty):
    with pytest.raises(ValueError, match='an empty namespace'):
        validate_namespace(empty)


@pytest.mark.parametrize('bad', ['/1fish', '/a//b', '/fish-1', '/a b'])
def test_invalid_namespaces_are_refused(bad):
    with pytest.raises(ValueError, match='invalid ROS namespace'):
        validate_namespace(bad)


# --- restart policy --------------------------------------------------------------------------

def test_restarts_back_off_and_the_budget_is_spent_after_max_restarts():
    budget = RestartBudget(RestartPolicy(delay_s=1.0, backoff=2.0, max_restarts=3,
                                         window_s=60.0))
    assert [budget.on_exit(t) for t in (0.0, 2.0, 5.0, 10.0)] == [1.0, 2.0, 4.0, None]
    assert budget.total == 3


def test_restarts_older_than_the_window_no_longer_count():
    budget = RestartBudget(RestartPolicy(delay_s=1.0, max_restarts=2, window_s=10.0))
    budget.on_exit(0.0)
    budget.on_exit(1.0)
    assert budget.on_exit(5.0) is None  # two within 10 s: spent
    assert budget.on_exit(12.0) == 1.0  # the first two left the window: the delay starts over


def test_the_back_off_is_capped():
    policy = RestartPolicy(delay_s=1.0, backoff=10.0, max_delay_s=5.0, max_restarts=9)
    assert [policy.delay_before(n) for n in (1, 2, 3)] == [1.0, 5.0, 5.0]


def test_a_policy_without_respawn_never_restarts():
    assert RestartBudget(RestartPolicy(respawn=False)).on_exit(0.0) is None


@pytest.mark.parametrize('field, value', [('delay_s', -1.0), ('window_s', float('nan')),
                                          ('backoff', 0.5), ('max_restarts', -1)])
def test_a_policy_that_cannot_be_honoured_is_refused(field, value):
    with pytest.raises(ValueError, match=field):
        RestartPolicy(**{field: value})


def test_the_fish_and_the_bridge_are_required_and_every_node_respawns():
    graph = {e.name: e.restart for e in entries(sim=True)}
    assert {name for name, p in graph.items() if p.required} == {'fish_sim', 'bridge_node'}
    assert all(p.respawn and p.max_restarts > 0 for p in graph.values())


def test_one_process_of_several_nodes_gets_the_strictest_policy():
    policy = combined_policy([RestartPolicy(max_restarts=5, delay_s=0.5),
                              RestartPolicy(max_restarts=2, delay_s=2.0, required=True)])
    assert (policy.max_restarts, policy.delay_s, policy.required) == (2, 2.0, True)


# --- the launch file reads the registry: its AST (test/bringup/test_launch_file.py runs it) -----

def _launch_tree() -> ast.Module:
    return ast.parse(LAUNCH_FILE.read_text(), filename=str(LAUNCH_FILE))


def _calls(tree: ast.AST, name: str) -> list[ast.Call]:
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)
            and isinstance(n.func, ast.Name) and n.func.id == name]


def test_the_launch_file_builds_its_nodes_from_the_registry():
    tree = _launch_tree()
    imports = {alias.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)
               and n.module == 'wirefish_bringup.graph' for alias in n.names}
    assert 'fish_graph' in imports and _calls(tree, 'fish_graph')
    [node] = _calls(tree, 'Node')
    keywords = {k.arg: k.value for k in node.keywords}
    for name in ('package', 'executable', 'name', 'namespace', 'parameters', 'respawn',
                 'respawn_delay', 'respawn_max_retries'):
        assert name in keywords, name
    spec_fields = set(NodeSpec.__dataclass_fields__)
    for name in ('package', 'executable', 'name', 'namespace'):
        value = keywords[name]
        assert isinstance(value, ast.Attribute) and value.attr in spec_fields, name
    restart = {ast.unparse(keywords[k])
               for k in ('respawn', 'respawn_delay', 'respawn_max_retries')}
    assert restart == {'spec.restart.respawn', 'spec.restart.delay_s',
                       'spec.restart.max_restarts'}
    assert isinstance(keywords['parameters'], ast.List)
    assert 'arguments' not in keywords or '--ros-args' not in ast.unparse(keywords['arguments'])


def test_every_launch_argument_has_a_description():
    declared = _calls(_launch_tree(), 'DeclareLaunchArgument')
    assert declared
    for call in declared:
        description = {k.arg: k.value for k in call.keywords}.get('description')
        assert isinstance(description, ast.Constant) and description.value.strip(), \
            ast.unparse(call.args[0])


def test_the_view_is_a_shore_process_started_only_when_asked():
    assert 'view_node' not in [s.name for s in fish_graph(sim=True, params_file='p.yaml')]
    with_view = fish_graph(sim=True, params_file='p.yaml', view=True)
    assert with_view[-1].name == 'view_node'
    assert 'view_node' in [e.name for e in entries(sim=True, role=Role.SHORE, view=True)]
    assert 'view_node' not in [e.name for e in entries(sim=True, role=Role.FISH, view=True)]


@pytest.mark.parametrize('options', [{}, {'single_process': True}, {'role': Role.FISH},
                                     {'qemu': True, 'sim': False}])
def test_every_process_of_a_graph_releases_the_stop_signals_it_is_started_with(options):
    # wirefish up starts these with SIGINT/SIGTERM blocked: one that never released them
    # could be stopped only by SIGKILL.
    specs = fish_graph('/g', **options)
    assert specs and all(spec.releases_stop_signals for spec in specs)


def test_a_process_outside_the_registry_is_not_trusted_to_release_them():
    assert not NodeSpec('wirefish_cpg', 'late_node', 'late_node').releases_stop_signals
