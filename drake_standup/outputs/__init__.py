"""What a run's logs become: signals, metrics, figures, the recording and JSON files."""
