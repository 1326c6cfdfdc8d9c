# SPDX-License-Identifier: Apache-2.0
"""
firmware/README.md held to the code it describes, in its own terms.

The FreeRTOS / STM32Cube section lists the functions of wf/hal.h that a project implements and
says how many there are: exactly the functions the header declares. The watchdog period it
gives follows from the IWDG's prescaler and reload in the port (RM0090 21.3.3: t = 4 x 2^PR x
(RLR + 1) / f_LSI) over the LSI's 17-47 kHz (datasheet, 32 kHz typical).
"""

import re

from firmware_host import FIRMWARE

README = (FIRMWARE / 'README.md').read_text()
HAL_H = (FIRMWARE / 'include' / 'wf' / 'hal.h').read_text()
FAILSAFE_C = (FIRMWARE / 'port' / 'stm32f4' / 'failsafe.c').read_text()
NUMBERS = {'seven': 7, 'eight': 8, 'nine': 9, 'ten': 10, 'eleven': 11, 'twelve': 12,
           'thirteen': 13, 'fourteen': 14, 'fifteen': 15}


def _cube_section() -> str:
    start = README.index('## Into an existing FreeRTOS / STM32Cube project')
    return README[start:README.index('\n## ', start + 1)]


def _declared() -> list[str]:
    code = re.sub(r'/\*.*?\*/', '', HAL_H, flags=re.S)
    return re.findall(r'^[A-Za-z_][\w \*]*?\b(wf_hal_\w+)\s*\(', code, flags=re.M)


def test_the_readme_lists_exactly_the_functions_hal_h_declares():
    listed = re.findall(r'^\| `(wf_hal_\w+)` \|', _cube_section(), flags=re.M)
    assert sorted(listed) == sorted(_declared()) and len(set(listed)) == len(listed)


def test_the_readme_counts_them_right():
    count = re.search(r'calls only the (\w+) functions of `wf/hal.h`', _cube_section())
    assert count is not None and NUMBERS[count.group(1)] == len(_declared())


def test_the_watchdog_period_the_readme_gives_is_the_ports():
    prescaler = int(re.search(r'IWDG_PRESCALER_DIV4 = (\d+)u', FAILSAFE_C).group(1))
    reload = int(re.search(r'IWDG_RELOAD = (\d+)u', FAILSAFE_C).group(1))
    ticks = 4 * 2 ** prescaler * (reload + 1)
    nominal, fastest, slowest = (round(1000 * ticks / hz) for hz in (32000, 47000, 17000))
    section = _cube_section()
    assert f'prescaler 4, reload {reload}: {nominal} ms, {fastest}-{slowest} ms' in section
    assert f'{nominal} ms nominal, {fastest}-{slowest} ms' in README
