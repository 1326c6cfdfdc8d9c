# SPDX-License-Identifier: Apache-2.0
"""
Point the ROS 2 wheels' exported CMake targets at this machine's include directories.

The PyPI wheels of ROS 2 Jazzy were built in a manylinux container; every exported
``*__rosidl_generator_py`` target names that container's Python and numpy include directories
(``/opt/python/cp311-cp311/...``), and CMake refuses to generate a build that imports a target
with a non-existent include path.  This rewrites those two paths, inside the virtual
environment only (no root needed), to the running interpreter's include directory and the
venv's numpy include directory.  Idempotent: a second run finds nothing to change.
"""

from pathlib import Path
import sys
import sysconfig

BUILD_PYTHON_INCLUDE = '/opt/python/cp311-cp311/include/python3.11'
BUILD_NUMPY_INCLUDE = '/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include'


def main(prefix: str) -> int:
    """Rewrite the include paths under ``prefix/share``; return a process exit code."""
    python_include = sysconfig.get_paths()['include']
    if not Path(python_include, 'Python.h').is_file():
        print(f'wirefish setup: Python headers missing ({python_include}/Python.h): '
              'install the python3-dev package of this Python', file=sys.stderr)
        return 1
    import numpy
    replacements = {
        BUILD_PYTHON_INCLUDE: python_include,
        BUILD_NUMPY_INCLUDE: numpy.get_include(),
    }
    patched = 0
    for path in Path(prefix, 'share').glob('*/cmake/*.cmake'):
        text = path.read_text()
        if '/opt/python/cp311-cp311' not in text:
            continue
        for old, new in replacements.items():
            text = text.replace(old, new)
        path.write_text(text)
        patched += 1
    print(f"wirefish setup: pointed {patched} CMake export files at this machine's includes")
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1]))
