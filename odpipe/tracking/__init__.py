"""The structure of a TrackingTable that every stage reads: count intervals from time tags
(:mod:`odpipe.tracking.timetags`), uplink ramp segments (:mod:`odpipe.tracking.ramp_segments`) and
tracking passes (:mod:`odpipe.tracking.passes`). Used by measurements, media, preprocess, od and products;
imports nothing of odpipe (numpy, pandas and ``parsers`` only)."""
