# SPDX-License-Identifier: Apache-2.0
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'wirefish_view'
# The dashboard bundle (web/dist, built by `make setup` with npm ci and esbuild), when built.
dashboard = [str(p) for p in sorted(Path('web/dist').glob('*')) if p.is_file()]

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/layouts', ['layouts/wirefish.json']),
        ('share/' + package_name + '/dashboard', dashboard),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='wirefish maintainers',
    maintainer_email='maintainers@wirefish.dev',
    description='A Foxglove WebSocket server over the graph, and a browser dashboard.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'view_node = wirefish_view.executables:view_node',
        ],
        'wirefish.commands': [
            'view = wirefish_view.verb.view',
        ],
    },
)
