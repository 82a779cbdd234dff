"""ament_python packaging for bayes_swarm; also what the development install uses."""

from pathlib import Path

from setuptools import find_packages, setup

PACKAGE_NAME = 'bayes_swarm'
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
    install_requires=['numpy', 'swarm_common', 'scipy', 'nlopt', 'swarm_runtime'],
    zip_safe=True,
    maintainer='Swarm search maintainers',
    maintainer_email='maintainers@swarm-search.org',
    description=(
        'Bayes-Swarm-P decentralized batch Bayesian source seeking and its baselines '
        '(Bayes-Swarm-O, Glowworm, Levy walk, exhaustive search).'
    ),
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'bayes_swarm_node = bayes_swarm.node:main',
        ],
    },
)
