"""Empirical atmosphere models and the solar/geomagnetic activity they take."""
