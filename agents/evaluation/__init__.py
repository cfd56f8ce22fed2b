"""Evaluation and reports: the one episode loop (:mod:`.episodes`), tables and figures,
``BENCHMARKS.md`` and recorded videos."""
