# SPDX-License-Identifier: Apache-2.0
"""
The firmware's cost: CPU cycles per received frame, telemetry frame and CPG step; flash, RAM.

Cycles come from the host build (``make -C firmware cycles``: one ``wf_app_poll`` timed with
the x86 time-stamp counter, 20,000 runs each): a poll that finds one SERVO_CMD, one that finds
the longest frame the decoder takes whole (62 bytes), one that sends the telemetry (with its
IMU sample, failsafe and servo update), one ``wf_cpg_step`` alone (eq 1, one RK4 step of
1 ms) and one poll in gait mode with nothing else due. The board's run is deterministic, so it
is repeated 5 times and each poll keeps its fastest repeat; the worst case quoted is the
slowest poll of those (the worst input without the scheduler's noise; the single slowest poll
seen, the scheduler's figure, is in the JSON as raw_max).

The CPG step on the board (``make -C firmware cpg-arm-count``): the instructions one step
executes on the Cortex-M4 build, counted in QEMU (1000 steps minus 0). QEMU models no cycle
timing, so the time is an estimate: t = N * c / f_clk with c = 1.2 to 1.5 cycles an
instruction (test/cpg_arm_count.c: most take one, loads, stores and taken branches two to
four) and f_clk = 168 MHz; 1691 instructions give 12.1 to 15.1 us, 1.2 to 1.5 % of the step's
1 ms period.

Flash (text + data) and RAM (data + bss, the stack included) are arm-none-eabi-size of the ARM
image for the STM32F407, when the cross compiler is installed.
"""

from __future__ import annotations

import json
from pathlib import Path
import re
import shutil
import subprocess

FIRMWARE = (Path(__file__).resolve().parents[3] / 'firmware'
            if (Path(__file__).resolve().parents[3] / 'firmware' / 'Makefile').is_file()
            else Path.cwd() / 'firmware')
FLASH_BUDGET_B = 32 * 1024
RAM_BUDGET_B = 8 * 1024
CLOCK_HZ = 168e6  # the STM32F407's SYSCLK (port/stm32f4/board.h)
CPG_STEP_S = 1e-3  # WF_CPG_STEP_MS: one CPG step per millisecond of the board's clock
# QEMU counts instructions, not cycles: test/cpg_arm_count.c puts the M4's cycles at about
# 1.2 to 1.5 times the count (one cycle for most, two to four for loads, stores, branches).
CYCLES_PER_INSTRUCTION = (1.2, 1.5)
_ARM_COUNT = re.compile(r'cpg_step on the Cortex-M4 build: (\d+) instructions')


def _make(*targets: str) -> str:
    return subprocess.run(['make', '-s', '-C', str(FIRMWARE), *targets], check=True,
                          capture_output=True, text=True, timeout=600).stdout


def image_size(elf: Path) -> dict[str, int]:
    """Return flash (text + data) and RAM (data + bss) of an ELF, from arm-none-eabi-size."""
    out = subprocess.run(['arm-none-eabi-size', '-B', str(elf)], check=True,
                         capture_output=True, text=True).stdout.splitlines()[1].split()
    text, data, bss = (int(v) for v in out[:3])
    return {'flash_B': text + data, 'ram_B': data + bss}


def arm_cpg_step(make_output: str) -> dict:
    """
    Return one CPG step on the Cortex-M4 from ``make cpg-arm-count``'s output.

    Instructions as counted, and the time they imply at 168 MHz as an estimate:
    t = N * c / f_clk for c in CYCLES_PER_INSTRUCTION, and t over the 1 ms step period.
    """
    match = _ARM_COUNT.search(make_output)
    if match is None:
        raise ValueError(f'make cpg-arm-count printed no instruction count: {make_output!r}')
    instructions = int(match.group(1))
    step_s = [instructions * c / CLOCK_HZ for c in CYCLES_PER_INSTRUCTION]
    return {'instructions': instructions, 'clock_hz': CLOCK_HZ,
            'cycles_per_instruction': list(CYCLES_PER_INSTRUCTION),
            'step_s_estimate': step_s,
            'share_of_step_period_estimate': [t / CPG_STEP_S for t in step_s]}


def run() -> dict:
    """Build and measure: the host cycles and, when the ARM tools are here, size and step."""
    _make('cycles')
    cycles = json.loads(subprocess.run([str(FIRMWARE / 'build' / 'host' / 'cycles')],
                                       check=True, capture_output=True, text=True,
                                       timeout=300).stdout)
    result: dict = {'cycles': cycles}
    if shutil.which('arm-none-eabi-gcc') is None:
        result['size'] = result['arm_cpg_step'] = {'error': 'arm-none-eabi-gcc not installed'}
        return result
    _make('arm')
    result['size'] = image_size(FIRMWARE / 'build' / 'arm' / 'wirefish.elf')
    result['arm_cpg_step'] = (arm_cpg_step(_make('cpg-arm-count'))
                              if shutil.which('qemu-system-arm') is not None
                              else {'error': 'qemu-system-arm not installed'})
    return result


def _arm_step(step: dict) -> str:
    if 'error' in step:
        return f'the CPG step on the Cortex-M4 not measured: {step["error"]}'
    low, high = (1e6 * t for t in step['step_s_estimate'])
    share_low, share_high = (100.0 * s for s in step['share_of_step_period_estimate'])
    c_low, c_high = step['cycles_per_instruction']
    return (f'one CPG step on the Cortex-M4: {step["instructions"]} instructions (counted in '
            f'QEMU), an estimated {low:.0f}-{high:.0f} µs at {step["clock_hz"] / 1e6:.0f} MHz '
            f'({c_low:g}-{c_high:g} cycles an instruction), {share_low:.1f}-{share_high:.1f} % '
            f'of its {1e3 * CPG_STEP_S:g} ms period')


def row(result: dict) -> tuple[str, str, str, str, str]:
    """Return the BENCHMARKS.md row: (figure, goal, measured, verdict, how)."""
    figure = ('Firmware: cycles per received frame / per telemetry frame / per CPG step (worst '
              'case), one CPG step on the Cortex-M4, flash / RAM of the STM32F407 image')
    goal = (f'≤ {FLASH_BUDGET_B // 1024} KB flash, ≤ {RAM_BUDGET_B // 1024} KB RAM (the cycles: '
            'reported)')
    if 'error' in result:
        return figure, goal, result['error'], 'not measured', ''
    c = result['cycles']
    unit = 'TSC ticks' if c['counter'] == 'tsc' else 'ns'

    def figure_of(name: str) -> str:
        return f'{c[name]["worst"]} (median {c[name]["median"]})'

    measured = (f'{unit}, worst of {c["telemetry_sent"]["runs"]} polls: SERVO_CMD received '
                f'{figure_of("servo_cmd_received")}, 62-byte frame received '
                f'{figure_of("longest_frame_received")}, telemetry sent '
                f'{figure_of("telemetry_sent")}; one CPG step {figure_of("cpg_step")}, a '
                f'gait-mode poll {figure_of("gait_poll")}; '
                + _arm_step(result.get('arm_cpg_step', {'error': 'not run'})))
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
            'each poll its fastest of 5 repeats, the CPG step (wf_cpg_step alone) and the '
            'gait-mode poll alike (firmware/test/cycles.c); make cpg-arm-count: the -Os M4 '
            'build of cpg.c in QEMU netduinoplus2, instructions of 1000 steps minus 0 '
            '(firmware/test/cpg_arm_count.c), time = instructions × cycles an instruction / '
            '168 MHz; arm-none-eabi-size -B of build/arm/wirefish.elf (-Os)')


if __name__ == '__main__':
    print(json.dumps(run(), indent=2))
