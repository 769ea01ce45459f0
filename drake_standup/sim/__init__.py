"""Building and running the diagram: the diagram, the runner, simulate, the psi = t
baseline, the run's folder, the live mode and the Meshcat visuals."""
