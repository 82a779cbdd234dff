"""Fake devices for tests and for running the driver nodes without hardware.

They emulate the devices at the byte/register level (an RPLidar answering requests and
streaming a synthetic room, SMBus register maps of the MPU6050, ADS1115 and Grove Base Hat,
the gas microcontroller's JSON protocol, a GPIO output line), so the real protocol and
device code runs against them unchanged.
"""
