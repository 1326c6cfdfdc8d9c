# SPDX-License-Identifier: Apache-2.0
"""Owner records of virtual-fish links: a live owner's link opens, a stale one does not."""

import json
import os
import subprocess
import sys

import pytest
from wirefish_bridge.link_owner import (open_refusal, owner_record_path, process_start,
                                        remove_owner_record, stale_link_problem,
                                        terminal_session, write_owner_record)


@pytest.fixture
def link(tmp_path):
    device = tmp_path / 'pts-7'   # stands in for the device: any existing path will do
    device.write_text('')
    path = tmp_path / 'fish-tty'
    os.symlink(device, path)
    return path


def test_a_port_without_owner_record_is_left_to_the_heartbeat_rule(link):
    assert stale_link_problem(str(link)) is None


def test_the_link_of_a_live_owner_is_not_stale(link):
    write_owner_record(link, os.readlink(link))
    assert stale_link_problem(str(link)) is None
    remove_owner_record(link)
    assert not owner_record_path(link).exists()


def test_the_link_of_a_dead_owner_is_stale(link):
    dead = subprocess.Popen([sys.executable, '-c', 'pass'])
    dead.wait()
    write_owner_record(link, os.readlink(link), pid=dead.pid)
    problem = stale_link_problem(str(link))
    assert problem is not None and f'owner (pid {dead.pid}) is gone' in problem


def test_a_reused_pid_is_not_taken_for_the_owner(link):
    record = {'pid': os.getpid(), 'start': process_start(os.getpid()) + 1,
              'device': os.readlink(link)}
    owner_record_path(link).write_text(json.dumps(record))
    assert 'is gone' in stale_link_problem(str(link))


def test_a_link_pointing_elsewhere_than_its_owner_serves_is_stale(link, tmp_path):
    write_owner_record(link, str(tmp_path / 'pts-8'))
    assert 'serves' in stale_link_problem(str(link))


@pytest.mark.parametrize('text', ['', '{', '{"pid": "x"}', '[]'])
def test_an_unreadable_record_refuses_the_port(link, text):
    owner_record_path(link).write_text(text)
    assert 'invalid' in stale_link_problem(str(link))


def test_process_start_is_known_for_a_running_process_only():
    assert process_start(os.getpid()) > 0
    assert process_start(2**22 + 12345) is None


@pytest.fixture
def terminal():
    """Yield (pty path, pid of a session leader whose controlling terminal it is)."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    shell = subprocess.Popen([sys.executable, '-c',
                              f'import os, sys; os.setsid(); os.open({path!r}, os.O_RDWR); '
                              'print(flush=True); sys.stdin.read()'],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    shell.stdout.readline()   # the terminal is its controlling terminal from here on
    yield path, shell.pid
    shell.communicate('')
    os.close(master)
    os.close(slave)


def test_a_controlling_terminal_is_refused_with_its_process(terminal):
    path, pid = terminal
    problem = open_refusal(path)
    assert problem is not None and f'controlling terminal of pid {pid}' in problem


def test_a_pty_that_is_nobody_s_terminal_may_be_opened(tmp_path):
    master, slave = os.openpty()
    try:
        assert terminal_session(os.ttyname(slave)) is None
        assert open_refusal(os.ttyname(slave)) is None
    finally:
        os.close(master)
        os.close(slave)


def test_a_path_that_is_no_device_has_no_terminal_session(link):
    assert terminal_session(str(link)) is None
