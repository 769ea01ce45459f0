"""Many runs: sweeps, the comparison of responses, the benchmarks and the convergence study."""
