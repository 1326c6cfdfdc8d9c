# SPDX-License-Identifier: Apache-2.0
from setuptools import find_packages, setup

package_name = 'wirefish_bridge'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'PROTOCOL.md', 'README.md']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='wirefish maintainers',
    maintainer_email='maintainers@wirefish.dev',
    description='Serial bridge to the fish STM32 board (protocol, codec, transport, bridge_node).',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'bridge_node = wirefish_bridge.executables:bridge_node',
        ],
    },
)
