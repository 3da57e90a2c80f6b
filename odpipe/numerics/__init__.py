"""Numerical building blocks shared by time, frames, environment and dynamics: uniform-grid Lagrange
interpolation (:mod:`odpipe.numerics.interpolation`), piecewise Chebyshev tables evaluable from numba
(:mod:`odpipe.numerics.chebyshev`), and figures printed at the precision they carry
(:mod:`odpipe.numerics.precision`). No model knowledge; imports nothing of odpipe."""
