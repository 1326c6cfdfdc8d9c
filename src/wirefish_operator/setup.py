# SPDX-License-Identifier: Apache-2.0
from glob import glob

from setuptools import find_packages, setup

package_name = 'wirefish_operator'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/missions', glob('missions/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='wirefish maintainers',
    maintainer_email='maintainers@wirefish.dev',
    description=("The operator's verbs: drive, missions, retune, the gait library, "
                 'topics and parameters.'),
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
        ],
        'wirefish.commands': [
            'retune = wirefish_operator.verb.retune',
            'hand-back = wirefish_operator.verb.hand_back',
            'gaits = wirefish_operator.verb.gaits',
            'drive = wirefish_operator.verb.drive',
            'mission = wirefish_operator.verb.mission',
            'topic = wirefish_operator.verb.topic',
            'param = wirefish_operator.verb.param',
            'calibrate = wirefish_operator.verb.calibrate',
        ],
    },
)
