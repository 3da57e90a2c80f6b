"""odpipe: orbit-determination post-processing for deep-space and cislunar tracking data."""

__version__ = "0.1.0"
