"""The one error a scenario's inputs raise: a one-line message naming the key or file."""


class ScenarioError(ValueError):
    """A scenario that cannot run; the message is one line naming the key."""
