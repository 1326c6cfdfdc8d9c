# SPDX-License-Identifier: Apache-2.0
"""
Fixtures of the two-host tests: a fish host and a shore host in two network namespaces.

The pair (``wirefish_launcher.netns.TwoHosts``) is made for each test and deleted at its end,
also when it fails; its names carry ``wf`` and a token of this run, its addresses are
10.213.<(WIREFISH_TEST_DOMAIN_BASE + n) % 256>.1/.2 for the n-th pair. Making namespaces needs
root: elsewhere every test here is skipped with the reason (CI runs as root, so they run
there).
"""

from collections.abc import Iterator
import itertools
import os

import pytest
from ros_utils import stop_process
from twohost.link_hosts import Hosts

DOMAIN_BASE = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21'))
_pairs = itertools.count()


@pytest.fixture
def hosts(request: pytest.FixtureRequest, tmp_path) -> Iterator[Hosts]:
    """
    Yield a fish host and a shore host joined by a veth pair; remove both at the end.

    DDS discovery across the pair is multicast unless the test asks for ``Discovery.STATIC``
    (``@pytest.mark.parametrize('hosts', [Discovery.STATIC], indirect=True)``).
    """
    from wirefish_launcher.netns import Discovery, root_problem, TwoHosts

    problem = root_problem()
    if problem is not None:
        pytest.skip(problem)
    # A pair of its own per test (names and subnet): nothing of the last test's pair is reused.
    index = next(_pairs)
    link = TwoHosts(f'{os.getpid():x}'[-5:] + str(index), (DOMAIN_BASE + index) % 256)
    link.remove()  # a pair of the same token left by a killed run
    link.create()
    hosts = Hosts(link, DOMAIN_BASE + 19, f'/h{DOMAIN_BASE}_twohost', tmp_path,
                  discovery=getattr(request, 'param', Discovery.MULTICAST))
    try:
        yield hosts
    finally:
        for proc in reversed(hosts.processes):
            code = stop_process(proc, timeout_s=15.0)
            tail = proc.stdout.read()[-2000:] if proc.stdout else ''
            print(f'--- {" ".join(proc.args[4:7])} (exit {code}) ---\n{tail}')
        link.remove()
        assert link.exists() == [], 'a network namespace of the test was left behind'
