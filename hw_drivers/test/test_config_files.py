"""config/*.yaml mirror the parameter tables: the documented defaults are the real ones."""

from pathlib import Path

import pytest
import yaml

from hw_drivers import (
    aoa_receiver_node,
    gas_node,
    mpu6050_node,
    pump_node,
    rplidar_node,
    static_frames_node,
)

CONFIG = Path(__file__).resolve().parents[1] / 'config'
NODES = {
    'rplidar_node': rplidar_node,
    'gas_adc_node': gas_node,
    'mpu6050_node': mpu6050_node,
    'aoa_receiver_node': aoa_receiver_node,
    'pump_node': pump_node,
    'static_frames_node': static_frames_node,
}


@pytest.mark.parametrize('name', sorted(NODES))
def test_config_file_lists_every_parameter_with_its_default(name):
    document = yaml.safe_load((CONFIG / f'{name}.yaml').read_text())
    params = document[f'/**/{name}']['ros__parameters']
    table = {pname: default for pname, default, _ in NODES[name].PARAMETERS}
    assert params == table


@pytest.mark.parametrize('name', sorted(NODES))
def test_every_parameter_has_a_description(name):
    assert all(description.strip() for _, _, description in NODES[name].PARAMETERS)
