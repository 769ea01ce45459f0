"""The stand-up: its state machine, the psi advancement, the CoM path, the tick's task
references, the contact schedule and the stand-up controller's diagram."""
