"""Hardware driver nodes: RPLidar A1, MP503 gas sensor through an ADC, MPU6050 IMU, Silicon Labs
BG22 AoA locator receiver, pump on a GPIO.
"""
