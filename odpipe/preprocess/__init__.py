"""Preprocessing of a TrackingTable: passes, Doppler compression and data editing.

Each stage takes a TrackingTable and returns a new one; rows are flagged with an
edit reason (:mod:`odpipe.preprocess.flags`), never dropped.
"""
