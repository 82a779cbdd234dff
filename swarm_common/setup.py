"""ament_python packaging for swarm_common; also what the development install uses."""

from setuptools import find_packages, setup

PACKAGE_NAME = 'swarm_common'

setup(
    name=PACKAGE_NAME,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    package_data={PACKAGE_NAME: ['py.typed']},
    data_files=[
        ('share/ament_index/resource_index/packages', [f'resource/{PACKAGE_NAME}']),
        (f'share/{PACKAGE_NAME}', ['package.xml']),
    ],
    install_requires=['numpy'],
    zip_safe=True,
    maintainer='Swarm search maintainers',
    maintainer_email='maintainers@swarm-search.org',
    description=(
        'Small ROS-free helpers every layer shares: angle wrapping, planar quaternions, '
        'stamp arithmetic, segment-disc entry, and the command-line error conventions.'
    ),
    license='Apache-2.0',
    entry_points={'console_scripts': []},
)
