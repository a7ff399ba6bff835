"""What every process of a run shares that is neither the model nor the bus: exit codes, signals and
the parent watch (lifecycle), the shared command-line arguments, and the run directory's files
(trajectory.csv, summary.json, plots), written by the engine's CLI and by the coordinator alike."""
