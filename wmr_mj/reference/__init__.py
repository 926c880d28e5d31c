"""Reference paths of point C and their conversion to the steering reference alpha0(t)."""
