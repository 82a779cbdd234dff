"""ament_python packaging for swarm_experiments; also what the development install uses."""

from pathlib import Path

from setuptools import find_packages, setup

PACKAGE_NAME = 'swarm_experiments'
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
        *share_files('launch'),
    ],
    install_requires=[
        'numpy',
        'matplotlib',
        'PyYAML',
        # Studies: results as Parquet, the distributed engine, progress.
        'pandas',
        'pyarrow',
        'dask',
        'distributed',
        'rich',
        'threadpoolctl',
        'swarm_common',
        'swarm_runtime',
        'swarm_analysis',
        'swarm_sim',
        'sim_bridge',
        # The spawners and batch runners run these algorithms.
        'oabug_robot',
        'bayes_swarm',
        'msc_pf',
    ],
    zip_safe=True,
    maintainer='Swarm search maintainers',
    maintainer_email='maintainers@swarm-search.org',
    description=(
        'Experiment harness: the spawners and their launch file, the mission loop, the batch '
        'runners of the benchmarks, the node parameter overrides and the studies (swarm_study).'
    ),
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'spawn = swarm_experiments.runtime_option:spawn_main',
            'spawn_bayes_swarm = swarm_experiments.runtime_option:spawn_bayes_swarm_main',
            'spawn_msc_pf = swarm_experiments.runtime_option:spawn_msc_pf_main',
            'swarm_study = swarm_experiments.study.cli:main',
        ],
        'swarm_experiments.studies': [
            'oabug = swarm_experiments.oabug_study:studies',
            'msc_pf = swarm_experiments.msc_pf_studies:studies',
            'bayes_swarm = swarm_experiments.bayes_studies:studies',
            'reliability = swarm_experiments.reliability:studies',
            'sgba = swarm_experiments.sgba_study:studies',
        ],
    },
)
