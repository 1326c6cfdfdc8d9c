# SPDX-License-Identifier: Apache-2.0
from setuptools import find_packages, setup

package_name = 'wirefish_analysis'

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
    description="Reproduce, sweep, calibrate and plot the paper's results; the benchmarks.",
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'reproduce_paper = wirefish_analysis.reproduce_paper:main',
            'calibrate_drag = wirefish_analysis.calibrate_drag:main',
            'identify_geometry = wirefish_analysis.verb.identify_geometry:main',
            'fig11 = wirefish_analysis.fig11:main',
            'servo_calibration = wirefish_analysis.servo_calibration:main',
            'plot_body_wave = wirefish_analysis.plot_body_wave:main',
        ],
        # Subcommands of the `wirefish` command that live here (see wirefish_cli.cli).
        'wirefish.commands': [
            'sweep = wirefish_analysis.verb.sweep',
            'identify-geometry = wirefish_analysis.verb.identify_geometry',
        ],
    },
)
