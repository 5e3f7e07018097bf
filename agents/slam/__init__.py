"""Seed 001: decentralised online SLAM by a robotic agent (RA) that deploys wireless agents (WAs)."""
