"""Runs: configuration files, run directories with manifests, reports, nightly batches."""
