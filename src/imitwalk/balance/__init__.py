"""Per-tick balance feedback: sensor channels, the state estimator, the per-tick phase
model, LQR gains, and learning the feedback laws by trials."""
