"""Responses outside the package, named by module:attribute in tests/plugins."""

from drake_standup.config.responses import Response

# psi runs ahead while the pull helps, and the CoM target also yields to the pull.
ADVANCE_AND_YIELD = Response(advances=True, lets_help_through=True, yields=True)
# The shipped stiff response, by another name.
STIFF_AGAIN = Response(advances=False, lets_help_through=False, yields=False)
NOT_A_RESPONSE = 3
