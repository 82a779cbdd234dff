"""ament_python packaging for msc_pf; also what the development install uses."""

from pathlib import Path

from setuptools import find_packages, setup

PACKAGE_NAME = 'msc_pf'
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
    ],
    install_requires=['numpy', 'swarm_common', 'swarm_runtime'],
    zip_safe=True,
    maintainer='Swarm search maintainers',
    maintainer_email='maintainers@swarm-search.org',
    description=(
        'Multi-target RSSI search and capture: MSC with a particle filter (proposed swarm'
        ' control) and the MSC and MSC+PF reference schemes.'
    ),
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'msc_pf_node = msc_pf.node:main',
        ],
    },
)
