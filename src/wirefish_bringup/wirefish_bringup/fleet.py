# SPDX-License-Identifier: Apache-2.0
"""
A fleet: several fish on one machine, each in a namespace of its own.

Fish ``i`` (1-based) of a fleet in ``base`` runs its whole graph (its own virtual fish, bridge,
CPG, kinematics, planner and tuner) in ``<base>/fish_<i>`` with frame ids under ``fish_<i>``
(``fish_1/base_link``), so the fleet shares one TF tree and one RViz. Each fish has its own
tuner: a retune names one fish's namespace and can reach no other fish's cpg_node (the tuner
calls the relative ``cpg_node``). One recorder (``--duration``) records the base namespace,
that is every fish. Two fleets in different base namespaces share no topic, service or
virtual-fish link: the namespace is in every name, and the link path is derived from it.
"""

from __future__ import annotations

from pathlib import Path

from wirefish_bringup.graph import (entry, fish_graph, NodeSpec, Role, sim_tty_link,
                                    validate_namespace, When)

SIMULATOR = 'fish_sim'  # the registry entry of the virtual fish

MAX_FLEET = 16  # each fish is ~6 processes and ~1 core-percent budget: a bound, not a goal


def fish_name(index: int) -> str:
    """Return the name of fish ``index`` (1-based): its namespace token and frame prefix."""
    return f'fish_{index}'


def fleet_namespaces(base: str, count: int) -> list[str]:
    """Return the namespaces of a fleet of ``count`` fish under ``base``."""
    base = validate_namespace(base)
    if not 1 <= count <= MAX_FLEET:
        raise ValueError(f'a fleet has 1 to {MAX_FLEET} fish, got {count}')
    return [f'{base.rstrip("/")}/{fish_name(i)}' for i in range(1, count + 1)]


def fleet_simulator(base: str, names: list[str], params_file: str) -> NodeSpec:
    """
    Return the one virtual-fish process of fish ``names`` in ``base`` (fish_1 ...).

    fish_sim runs in ``base`` with one ``--link`` per fish (the link that fish's bridge opens,
    ``sim_tty_link(<base>/<name>)``) and ``--fish <name>``: each fish's ground truth goes to
    ``<base>/<name>/sim/ground_truth`` with frames ``<name>/odom``, as the fish's own process did.
    """
    e = entry(SIMULATOR)
    base = validate_namespace(base)
    links = tuple(sim_tty_link(f'{base.rstrip("/")}/{name}') for name in names)
    own = ('--link', '{device}')  # the lone fish's link: one per fish instead
    return NodeSpec(e.package, e.executable, e.name,
                    arguments=(*(a for link in links for a in ('--link', str(link))),
                               *(a for name in names for a in ('--fish', name)),
                               *(a for a in e.arguments if a not in own)),
                    namespace=base, params_file=params_file, restart=e.restart,
                    ros_nodes=(e.name,), links=links)


def fleet_graph(base: str, count: int, *, params_file: Path | str | None = None,
                bag: Path | None = None, role: str = Role.ALL) -> list[NodeSpec]:
    """
    Return the processes of a fleet of virtual fish: the virtual fish, each graph, a recorder.

    One fish_sim for every fish first (``fleet_simulator``; none with the shore role), then
    fish by fish in start order; ``bag`` adds one recorder of the base namespace (every fish)
    at the end.
    """
    specs: list[NodeSpec] = []
    names = [fish_name(i) for i in range(1, count + 1)]
    for name, namespace in zip(names, fleet_namespaces(base, count)):
        specs += fish_graph(namespace, sim=True, params_file=params_file, role=role,
                            frame_prefix=name)
    simulators = [s for s in specs if s.name == SIMULATOR]
    specs = [s for s in specs if s.name != SIMULATOR]
    if simulators:  # not on the shore's side of a radio link
        specs.insert(0, fleet_simulator(base, names, str(simulators[0].params_file)))
    if bag is not None:
        specs += [s for s in fish_graph(base, sim=True, params_file=params_file, bag=bag)
                  if entry(s.name).when == When.RECORD]
    return specs
