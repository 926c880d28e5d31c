"""Steering controllers for wmr-mj (steering state and reference in, armature voltage out)."""
