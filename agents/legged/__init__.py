"""Legged robots: kinematics, gaits and the SMART robots Robot3L and Robot4L."""
