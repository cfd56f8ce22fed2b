"""``motiongym bench``: throughput and memory as ratios against references timed in the same run."""
