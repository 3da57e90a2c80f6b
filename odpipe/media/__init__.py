"""Media calibrations: troposphere and ionosphere delays for ground radiometric data.

Models are pure functions of elevation, site, time and frequency (``niell``,
``saastamoinen``, ``seasonal``, ``ionosphere``); ``apply`` adds per-leg
corrections to a TrackingTable.
"""
