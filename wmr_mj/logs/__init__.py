"""Run logs: the MCAP format, writer, reader, Foxglove encoders, replay and video."""
