"""The web front of seed 003: a page and an HTTP API planning uploads, samples and signs on Dask (docs/web.md)."""
