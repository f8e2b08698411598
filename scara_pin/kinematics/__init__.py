"""Kinematics of each robot kind: the planar-2R engine, the SCARA and palletizer closed forms, numeric IK."""
