"""odpipe: orbit-determination post-processing for deep-space and cislunar tracking data."""

import os

# The filter's matrices are small (tens of parameters): BLAS threads only add contention,
# measured ~10x slower on a busy 2-core machine. Applies when odpipe is imported before numpy;
# an explicit setting in the environment wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

__version__ = "0.1.0"
