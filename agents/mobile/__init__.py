"""Shared pieces of wheeled mobile robots: mazes and offices as worlds, a kinematic
differential drive with wheel encoders, ray sensors."""
