"""The named payloads between systems and their cached outputs (the lowest layer)."""
