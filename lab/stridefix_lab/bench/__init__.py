"""The benchmarks: one module each with a ``BENCH`` entry (:mod:`.registry`), plus their helpers."""
