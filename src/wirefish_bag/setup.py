# SPDX-License-Identifier: Apache-2.0
from setuptools import find_packages, setup

package_name = 'wirefish_bag'

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
    description=('Rosbag2 (MCAP) recording, recovery, replay and reports: the recorder '
                 'and the bag verbs.'),
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'recorder = wirefish_bag.executables:recorder',
        ],
        'wirefish.commands': [
            'record = wirefish_bag.verb.record',
            'bag = wirefish_bag.verb.bag',
            'play = wirefish_bag.verb.play',
            'report = wirefish_bag.verb.report',
        ],
    },
)
