"""Seed 000's decentralised communication framework: five processes, history-based
transfer, a radio with walls, and the mapping mission's nets and metrics."""
