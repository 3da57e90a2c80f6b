"""Numerical building blocks shared by time, frames, environment and dynamics: uniform-grid Lagrange
interpolation (:mod:`odpipe.numerics.interpolation`) and piecewise Chebyshev tables evaluable from numba
(:mod:`odpipe.numerics.chebyshev`). No model knowledge; imports nothing of odpipe."""
