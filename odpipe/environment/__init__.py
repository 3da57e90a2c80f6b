"""The run's environment: EOP, ephemerides, stations, gravity fields (read-only once built)."""
