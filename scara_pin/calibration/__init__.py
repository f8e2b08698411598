"""Kinematic calibration: identify a robot's description from measured tool positions."""
