"""Hardware driver nodes: RPLidar A1, MP503 gas sensor through an ADC, MPU6050 IMU, Silicon Labs
BG22 AoA locator receiver, pump on a GPIO.

Per device three layers (docs/hardware.md explains wiring, permissions and bringup):

* protocol, pure functions on bytes/registers: ``rplidar_protocol``, ``gas_protocol``,
  ``mpu6050_protocol`` (+ ``heading``), ``aoa_protocol``, ``pump_control``;
* device I/O behind small interfaces that tests fake: ``rplidar_device``, ``gas_device``,
  ``mpu6050_device``, ``aoa_server`` (+ ``aoa_bearings``), ``pump_output``, over
  ``serial_transport`` / ``i2c_transport``, run by the reconnecting ``worker``;
* thin nodes: ``rplidar_node``, ``gas_node``, ``mpu6050_node``, ``aoa_receiver_node``,
  ``pump_node``, translating through ``conversions`` with ``node_common`` helpers.

``errors`` holds the exception hierarchy (recoverable vs fatal), ``fakes`` the byte/register
level fakes used by tests and by ``fake_device:=true``, ``robot_bringup`` the supervised
bringup of one robot (``launch/robot.launch.py`` starts the same nodes).
"""
