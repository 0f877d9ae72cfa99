"""StrideFix lab: benchmarks, leave-one-walk-out real-data benches and the papers' experiments.

It measures the product (:mod:`stridefix_analyzer`, :mod:`stridefix_sim`, the firmware it runs) and
ships with the checkout, not in a logger's install; the product never imports it.
"""
