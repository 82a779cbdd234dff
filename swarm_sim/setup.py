"""ament_python packaging for swarm_sim; also what the development install uses."""

from pathlib import Path

from setuptools import find_packages, setup

PACKAGE_NAME = 'swarm_sim'
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
        *share_files('config/sites'),
    ],
    install_requires=[
        'numpy',
        'scipy',
        'matplotlib',
        'pybullet',
        # The compiled ray casting, world and sensor kernels (simulation only, like pybullet).
        'numba',
        'PyYAML',
        'swarm_common',
    ],
    zip_safe=True,
    maintainer='Swarm search maintainers',
    maintainer_email='maintainers@swarm-search.org',
    description=(
        'ROS-free simulator: world, geometry, ray casting, sensor models, sites (generator, '
        '.lay importer, site files), signal fields and RSSI targets, with numpy/numba and '
        'pybullet backends.'
    ),
    license='Apache-2.0',
    entry_points={
        'console_scripts': ['site_tool = swarm_sim.sites.cli:main'],
    },
)
