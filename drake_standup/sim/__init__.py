"""Building and running the diagram: the diagram, the runner, simulate, the psi = t baseline, the live mode and the Meshcat visuals."""
