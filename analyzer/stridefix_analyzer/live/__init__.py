"""``stridefix live``: a browser view of a walk as it happens (LCM in, a page on 127.0.0.1 out)."""
