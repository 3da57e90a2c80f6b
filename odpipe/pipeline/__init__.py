"""The whole chain for one arc, from a run configuration: ingest → geometry → calibrate →
compress → edit → fit → products (see :func:`odpipe.pipeline.run.run_config`)."""
