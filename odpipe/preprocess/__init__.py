"""Preprocessing of a TrackingTable: Doppler compression and data editing.

Passes, ramp segments and count intervals are the table's structure (:mod:`odpipe.tracking`).

Each stage takes a TrackingTable and returns a new one; rows are flagged with an
edit reason (:mod:`odpipe.preprocess.flags`), never dropped.
"""
