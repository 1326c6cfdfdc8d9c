# SPDX-License-Identifier: Apache-2.0
"""The pty link a killed virtual fish leaves behind is removed before a new one starts."""

import os

from wirefish_launcher.supervisor import remove_stale_link


def test_a_stale_pty_link_is_removed_and_a_missing_one_is_fine(tmp_path):
    link = tmp_path / 'wirefish-x-tty'
    os.symlink('/dev/pts/999999', link)  # what a killed virtual fish leaves behind
    remove_stale_link(link)
    assert not link.is_symlink()
    remove_stale_link(link)  # nothing there: nothing to do
