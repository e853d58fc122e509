"""Experiments: config in, run directory out. They never print; the CLI reports their progress."""
