"""Navigation products made from a solution: trajectories (OEM, SPK), tables, plots, reports."""
