"""
Fixtures of the two-host tests: a fish host and a shore host in two network namespaces.

The pair (``wirefish_bringup.netns.TwoHosts``) is made for this module and deleted at its end,
also when a test fails; its names carry ``wf`` and a token of this run, its addresses are
10.213.<WIREFISH_TEST_DOMAIN_BASE % 256>.1/.2. Making namespaces needs root: elsewhere every
test here is skipped with the reason (CI runs as root, so they run there).
"""

from collections.abc import Iterator
import os

import pytest
from ros_utils import stop_process
from twohost.link_hosts import Hosts

DOMAIN_BASE = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21'))


@pytest.fixture(scope='module')
def hosts(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Hosts]:
    """Yield a fish host and a shore host joined by a veth pair; remove both at the end."""
    from wirefish_bringup.netns import root_problem, TwoHosts

    problem = root_problem()
    if problem is not None:
        pytest.skip(problem)
    link = TwoHosts(f'{os.getpid():x}'[-6:], DOMAIN_BASE % 256)
    link.remove()  # a pair of the same token left by a killed run
    link.create()
    hosts = Hosts(link, DOMAIN_BASE + 19, f'/h{DOMAIN_BASE}_twohost',
                  tmp_path_factory.mktemp('twohost'))
    try:
        yield hosts
    finally:
        for proc in reversed(hosts.processes):
            code = stop_process(proc, timeout_s=15.0)
            tail = proc.stdout.read()[-2000:] if proc.stdout else ''
            print(f'--- {" ".join(proc.args[4:7])} (exit {code}) ---\n{tail}')
        link.remove()
        assert link.exists() == [], 'a network namespace of the test was left behind'
