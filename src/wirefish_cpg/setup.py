# SPDX-License-Identifier: Apache-2.0
from setuptools import find_packages, setup

package_name = 'wirefish_cpg'

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
    description="The fish's Ijspeert CPG (eq 1): the cpg node, its gaits and the gait library.",
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'cpg_node = wirefish_cpg.executables:cpg_node',
        ],
    },
)
