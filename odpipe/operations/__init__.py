"""Operations: the configuration schema and its reference, run folders with manifests, reports, nightly batches."""
