# SPDX-License-Identifier: Apache-2.0
from setuptools import find_packages, setup

package_name = 'wirefish_launcher'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='wirefish maintainers',
    maintainer_email='maintainers@wirefish.dev',
    description=('Process management: wirefish up, its supervisor and status, the '
                 'emulated board, two-host runs.'),
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'qemu_board = wirefish_launcher.executables:qemu_board',
            'compose = wirefish_launcher.executables:compose',
        ],
        'wirefish.commands': [
            'up = wirefish_launcher.verb.up',
            'qemu = wirefish_launcher.verb.qemu',
            'compose = wirefish_launcher.verb.compose',
            'twohost = wirefish_launcher.verb.twohost',
        ],
    },
)
