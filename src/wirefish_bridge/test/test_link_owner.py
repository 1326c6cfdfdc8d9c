"""Owner records of virtual-fish links: a live owner's link opens, a stale one does not."""

import json
import os
import subprocess
import sys

import pytest
from wirefish_bridge.link_owner import (owner_record_path, process_start, remove_owner_record,
                                        stale_link_problem, write_owner_record)


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
