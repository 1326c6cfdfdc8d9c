"""
The firmware's cost: CPU cycles per received frame and per telemetry frame, flash and RAM.

Cycles come from the host build (``make -C firmware cycles``: one ``wf_app_poll`` timed with
the x86 time-stamp counter, 20,000 runs each): a poll that finds one SERVO_CMD, one that finds
the longest frame the decoder takes whole (62 bytes), and one that sends the telemetry (with
its IMU sample, failsafe and servo update). The board's run is deterministic, so it is
repeated 5 times and each poll keeps its fastest repeat; the worst case quoted is the slowest
poll of those (the worst input without the scheduler's noise; the single slowest poll seen,
the scheduler's figure, is in the JSON as raw_max).
Flash (text + data) and RAM (data + bss, the stack included) are arm-none-eabi-size of the ARM
image for the STM32F407, when the cross compiler is installed.
"""

from __future__ import annotations

import json
from pathlib import Path
import shutil
import subprocess

FIRMWARE = (Path(__file__).resolve().parents[3] / 'firmware'
            if (Path(__file__).resolve().parents[3] / 'firmware' / 'Makefile').is_file()
            else Path.cwd() / 'firmware')
FLASH_BUDGET_B = 32 * 1024
RAM_BUDGET_B = 8 * 1024


def _make(*targets: str) -> None:
    subprocess.run(['make', '-s', '-C', str(FIRMWARE), *targets], check=True,
                   capture_output=True, text=True, timeout=600)


def image_size(elf: Path) -> dict[str, int]:
    """Return flash (text + data) and RAM (data + bss) of an ELF, from arm-none-eabi-size."""
    out = subprocess.run(['arm-none-eabi-size', '-B', str(elf)], check=True,
                         capture_output=True, text=True).stdout.splitlines()[1].split()
    text, data, bss = (int(v) for v in out[:3])
    return {'flash_B': text + data, 'ram_B': data + bss}


def run() -> dict:
    """Build and measure; return the cycle figures and, when it can be built, the ARM size."""
    _make('cycles')
    cycles = json.loads(subprocess.run([str(FIRMWARE / 'build' / 'host' / 'cycles')],
                                       check=True, capture_output=True, text=True,
                                       timeout=300).stdout)
    result: dict = {'cycles': cycles}
    if shutil.which('arm-none-eabi-gcc') is None:
        result['size'] = {'error': 'arm-none-eabi-gcc not installed'}
        return result
    _make('arm')
    result['size'] = image_size(FIRMWARE / 'build' / 'arm' / 'wirefish.elf')
    return result


def row(result: dict) -> tuple[str, str, str, str, str]:
    """Return the BENCHMARKS.md row: (figure, goal, measured, verdict, how)."""
    figure = ('Firmware: cycles per received frame / per telemetry frame (worst case), '
              'flash / RAM of the STM32F407 image')
    goal = f'≤ {FLASH_BUDGET_B // 1024} KB flash, ≤ {RAM_BUDGET_B // 1024} KB RAM'
    if 'error' in result:
        return figure, goal, result['error'], 'not measured', ''
    c = result['cycles']
    unit = 'TSC ticks' if c['counter'] == 'tsc' else 'ns'

    def figure_of(name: str) -> str:
        return f'{c[name]["worst"]} (median {c[name]["median"]})'

    measured = (f'{unit}, worst of {c["telemetry_sent"]["runs"]} polls: SERVO_CMD received '
                f'{figure_of("servo_cmd_received")}, 62-byte frame received '
                f'{figure_of("longest_frame_received")}, telemetry sent '
                f'{figure_of("telemetry_sent")}')
    size = result.get('size', {})
    if 'error' in size:
        measured += f'; size not measured: {size["error"]}'
        verdict = 'not measured'
    else:
        measured += f'; flash {size["flash_B"]} B, RAM {size["ram_B"]} B (stack included)'
        verdict = ('met' if size['flash_B'] <= FLASH_BUDGET_B and size['ram_B'] <= RAM_BUDGET_B
                   else 'missed')
    return (figure, goal, measured, verdict,
            'host build (x86-64, -O2), one wf_app_poll timed with rdtscp, 20,000 runs each, '
            'each poll its fastest of 5 repeats (firmware/test/cycles.c); arm-none-eabi-size '
            '-B of build/arm/wirefish.elf (-Os)')


if __name__ == '__main__':
    print(json.dumps(run(), indent=2))
