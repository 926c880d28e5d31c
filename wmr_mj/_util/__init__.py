"""Internal helpers shared by every layer: atomic files, memory checks, progress, resources."""
