# SPDX-License-Identifier: Apache-2.0
"""Builds of the emulator image from one firmware tree take turns (qemu_board.build_image)."""

from concurrent.futures import ThreadPoolExecutor

from wirefish_launcher.qemu_board import build_image, IMAGE

# A stand-in firmware tree whose build fails when another is inside it at the same time.
MAKEFILE = ('qemu:\n'
            '\tmkdir -p build && mkdir build/busy\n'
            '\tsleep 0.3\n'
            '\trmdir build/busy\n'
            '\tmkdir -p build/qemu && touch build/qemu/wirefish.elf\n')


def test_two_builds_started_at_once_both_succeed_one_after_the_other(tmp_path):
    (tmp_path / 'Makefile').write_text(MAKEFILE)
    with ThreadPoolExecutor(2) as pool:
        images = list(pool.map(lambda _: build_image(tmp_path), range(2)))
    assert images == [tmp_path / IMAGE] * 2
