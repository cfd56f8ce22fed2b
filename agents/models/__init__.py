"""Model files and shipping: reading model folders without unpickling, predictors, manifests,
and the shipped models in ``pretrained/``."""
