"""Training: SB3 runs from ``configs/``, DAgger, residual agents, behaviour cloning, and the
vector-env adapters (a native vector env, a PettingZoo env's agents) that SB3 trains on."""
