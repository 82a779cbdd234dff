"""ament_python packaging for hw_drivers; also what the development install uses."""

from pathlib import Path

from setuptools import find_packages, setup

PACKAGE_NAME = 'hw_drivers'
HERE = Path(__file__).resolve().parent


def share_files(subdir: str) -> list[tuple[str, list[str]]]:
    """Install every file under ``subdir`` into share/<package>/<subdir>."""
    files = sorted(str(f.relative_to(HERE)) for f in (HERE / subdir).glob('*') if f.is_file())
    return [(f'share/{PACKAGE_NAME}/{subdir}', files)] if files else []


setup(
    name=PACKAGE_NAME,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    package_data={PACKAGE_NAME: ['py.typed']},
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{PACKAGE_NAME}']),
        (f'share/{PACKAGE_NAME}', ['package.xml']),
        *share_files('config'),
        *share_files('bringup'),
        *share_files('launch'),
    ],
    install_requires=[
        'numpy',
        'swarm_common',
        'pyserial',
        'smbus2',
        'gpiod',
        'PyYAML',
        'swarm_runtime',
    ],
    zip_safe=True,
    maintainer='Swarm search maintainers',
    maintainer_email='maintainers@swarm-search.org',
    description=(
        'Hardware driver nodes: RPLidar A1, MP503 gas sensor through an ADC, MPU6050 IMU,'
        ' Silicon Labs BG22 AoA locator receiver, pump on a GPIO.'
    ),
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'rplidar_node = hw_drivers.rplidar_node:main',
            'gas_adc_node = hw_drivers.gas_node:main',
            'mpu6050_node = hw_drivers.mpu6050_node:main',
            'aoa_receiver_node = hw_drivers.aoa_receiver_node:main',
            'pump_node = hw_drivers.pump_node:main',
            'static_frames_node = hw_drivers.static_frames_node:main',
            'pump_off = hw_drivers.pump_off:main',
            'robot_bringup = hw_drivers.robot_bringup.cli:main',
        ],
    },
)
