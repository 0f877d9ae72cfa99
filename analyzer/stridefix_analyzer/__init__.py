"""StrideFix analyzer: reads LCM logs, scores POSE against TRUTH, writes metrics and reports."""
