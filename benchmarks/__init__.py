"""Benchmarks of the compiled kernel: ``python -m benchmarks`` (``make bench``)."""
