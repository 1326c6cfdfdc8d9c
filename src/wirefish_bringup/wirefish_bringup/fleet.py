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

from wirefish_bringup.graph import (ALL, entry, fish_graph, NodeSpec, RECORD,
                                    validate_namespace)

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


def fleet_graph(base: str, count: int, *, params_file: Path | str | None = None,
                bag: Path | None = None, role: str = ALL) -> list[NodeSpec]:
    """
    Return the processes of a fleet of virtual fish: every fish's graph, then one recorder.

    Fish by fish in start order (fish_1's virtual fish first); ``bag`` adds one recorder of
    the base namespace (every fish) at the end.
    """
    specs: list[NodeSpec] = []
    for index, namespace in enumerate(fleet_namespaces(base, count), start=1):
        specs += fish_graph(namespace, sim=True, params_file=params_file, role=role,
                            frame_prefix=fish_name(index))
    if bag is not None:
        specs += [s for s in fish_graph(base, sim=True, params_file=params_file, bag=bag)
                  if entry(s.name).when == RECORD]
    return specs
