"""Other tools' formats and runners: rl-zoo3 settings, Ray Tune sweeps, RLlib, Minari datasets."""
