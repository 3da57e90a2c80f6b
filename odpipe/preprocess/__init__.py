"""Preprocessing of a TrackingTable: Doppler compression and data editing (passes: :mod:`odpipe.tracking.passes`).

Each stage takes a TrackingTable and returns a new one; rows are flagged with an
edit reason (:mod:`odpipe.preprocess.flags`), never dropped.
"""
