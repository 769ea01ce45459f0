"""A lab's own plug-ins for drake_standup: an advancement law (laws.py) and a helper
(helpers.py), named in a scenario by entry point (gated, sway) or by module:attribute."""
