# SPDX-License-Identifier: Apache-2.0
"""
Fixtures of the two-host tests: a fish host and a shore host in two network namespaces.

The pair (``wirefish_launcher.netns.TwoHosts``) is made for each test (``hosts``) or module
(``module_hosts``) and deleted at its end, also when it fails; its names carry ``wf`` and a
token of this run, its addresses are 10.213.<(WIREFISH_TEST_DOMAIN_BASE + n) % 256>.1/.2 for
the n-th pair. Making namespaces needs root: elsewhere every test using them is skipped with
the reason (CI runs as root, so they run there).
"""

from collections.abc import Iterator
from contextlib import contextmanager
import itertools
import os
from pathlib import Path

from link_hosts import Hosts
import pytest
from ros_utils import stop_process

DOMAIN_BASE = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21'))
_pairs = itertools.count()


@contextmanager
def _pair_of_hosts(directory: Path, discovery) -> Iterator[Hosts]:
    from wirefish_launcher.netns import root_problem, TwoHosts

    problem = root_problem()
    if problem is not None:
        pytest.skip(problem)
    # A pair of its own per use (names and subnet): nothing of the last pair is reused.
    index = next(_pairs)
    link = TwoHosts(f'{os.getpid():x}'[-5:] + str(index), (DOMAIN_BASE + index) % 256)
    link.remove()  # a pair of the same token left by a killed run
    link.create()
    hosts = Hosts(link, DOMAIN_BASE + 19, f'/h{DOMAIN_BASE}_twohost', directory,
                  discovery=discovery)
    try:
        yield hosts
    finally:
        for proc in reversed(hosts.processes):
            code = stop_process(proc, timeout_s=15.0)
            tail = proc.stdout.read()[-2000:] if proc.stdout else ''
            print(f'--- {" ".join(proc.args[4:7])} (exit {code}) ---\n{tail}')
        link.remove()
        assert link.exists() == [], 'a network namespace of the test was left behind'


@pytest.fixture
def hosts(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Hosts]:
    """
    Yield a fish host and a shore host joined by a veth pair; remove both at the end.

    DDS discovery across the pair is multicast unless the test asks for ``Discovery.STATIC``
    (``@pytest.mark.parametrize('hosts', [Discovery.STATIC], indirect=True)``).
    """
    from wirefish_launcher.netns import Discovery

    with _pair_of_hosts(tmp_path, getattr(request, 'param', Discovery.MULTICAST)) as pair:
        yield pair


@pytest.fixture(scope='module')
def module_hosts(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Hosts]:
    """Yield one pair of hosts (multicast discovery) for all of a module's tests."""
    from wirefish_launcher.netns import Discovery

    with _pair_of_hosts(tmp_path_factory.mktemp('hosts'), Discovery.MULTICAST) as pair:
        yield pair
