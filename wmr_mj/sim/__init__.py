"""Simulation: run configuration, closed loop, batch engine and compiled law, sweeps, falsification, designs."""
