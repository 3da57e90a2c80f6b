"""Analysis of solutions: overlap precision, observability, covariance."""
