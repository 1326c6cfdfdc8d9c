# SPDX-License-Identifier: Apache-2.0
"""
Checks of what a user names on the command line: a port, a parameter file, a bag, a speed.

The speed is the pace of the virtual fish's clock (``parse_speed``).

Each check returns why its input cannot work, in one line, or None. `wirefish up` checks
before it starts anything: the graph would otherwise start and fail where a user does not
look (the bridge's log, a node's traceback).
"""

import math
import os
from pathlib import Path
import stat

import yaml

SYS_CHAR_DEVICES = Path('/sys/dev/char')


def _kind(mode: int) -> str:
    if stat.S_ISREG(mode):
        return 'a regular file'
    if stat.S_ISDIR(mode):
        return 'a directory'
    if stat.S_ISBLK(mode):
        return 'a block device'
    return 'not a device'


def serial_port_problem(port: str, sys_char_devices: Path = SYS_CHAR_DEVICES) -> str | None:
    """
    Return why ``port`` cannot be a fish's serial device, or None (also when it is not there).

    A port that does not exist yet is no problem here (a USB adapter may be plugged in later:
    the bridge retries). One that exists must be a character device of the kernel's tty class
    (ttyUSB, ttyACM, ttyS, a pty): /dev/null is a character device of class mem. A device that
    sysfs does not list (a pty) is taken as a terminal.
    """
    try:
        mode = os.stat(port).st_mode
        device = os.stat(port).st_rdev
    except FileNotFoundError:
        return None
    except OSError as error:
        return f'--port {port}: {error.strerror}'
    if not stat.S_ISCHR(mode):
        return f'--port {port} is {_kind(mode)}, not a serial device (e.g. /dev/ttyUSB0)'
    subsystem = sys_char_devices / f'{os.major(device)}:{os.minor(device)}' / 'subsystem'
    if subsystem.exists() and subsystem.resolve().name != 'tty':
        return (f'--port {port} is a {subsystem.resolve().name} device, not a serial port '
                '(a tty such as /dev/ttyUSB0 or /dev/ttyACM0)')
    return None


def params_file_problem(path: Path) -> str | None:
    """Return why ``path`` is not a ROS parameter file the nodes can read, or None."""
    if not path.exists():
        return f'--params-file {path} does not exist'
    if not path.is_file():
        return f'--params-file {path} is not a file'
    try:
        content = yaml.safe_load(path.read_text(encoding='utf-8'))
    except (OSError, UnicodeDecodeError) as error:
        return f'--params-file {path}: cannot read it ({error})'
    except yaml.YAMLError as error:
        where = getattr(error, 'problem_mark', None)
        line = f' at line {where.line + 1}' if where is not None else ''
        return f'--params-file {path} is not valid YAML{line}'
    expected = ('is not a ROS parameter file: expected <node name>: {ros__parameters: {...}} '
                'blocks (see the installed config/wirefish.yaml)')
    if not isinstance(content, dict) or not content:
        return f'--params-file {path} {expected}'
    for name, block in content.items():
        if not (isinstance(block, dict) and isinstance(block.get('ros__parameters'), dict)):
            return f'--params-file {path}: {name} {expected}'
    return None


def bag_directory_problem(bag: Path) -> str | None:
    """Return why ``bag`` is not a rosbag2 directory with MCAP files (any state), or None."""
    if not bag.exists():
        return f'{bag} does not exist'
    if not bag.is_dir():
        return f'{bag} is not a directory (a rosbag2 bag is one)'
    if not any(bag.glob('*.mcap')):
        return f'{bag} holds no .mcap file: not a rosbag2 bag, nothing was recorded there'
    return None


def parse_speed(text: str) -> float:
    """
    Return a ``--speed`` (the virtual fish's pace): a factor on real time > 0, or ``max``.

    ``max`` is ``math.inf``: as fast as the graph answers. Raises ValueError saying why not.
    """
    if text.strip().lower() == 'max':
        return math.inf
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f'--speed takes a factor on real time (e.g. 1, 4) or max, got {text!r}'
                         ) from None
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f'--speed must be finite and > 0 (or max), got {text!r}')
    return value


def speed_text(speed: float) -> str:
    """Return ``speed`` as ``--speed`` spells it (``max`` for ``math.inf``)."""
    return 'max' if math.isinf(speed) else f'{speed:g}'
