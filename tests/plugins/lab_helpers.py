"""Helpers outside the package, named by module:attribute in tests/plugins."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from drake_standup.plugins import HandWrenchHelper


class Steady(HandWrenchHelper):
    """15 N forward and up on each hand from 3 s (docs/extending.md's helper)."""

    def hand_wrenches(self, time_s, robot_state):
        w = np.zeros((2, 6))
        if time_s > 3.0:
            w[:, 3] = w[:, 5] = 15.0
        return w


class Twisting(HandWrenchHelper):
    """A torque about z on the left hand only, from 1 s."""

    def hand_wrenches(self, time_s, robot_state):
        w = np.zeros(12)
        if time_s > 1.0:
            w[2] = 2.0
        return w


class WrongShape(HandWrenchHelper):
    def hand_wrenches(self, time_s, robot_state):
        return np.zeros(6)


def portless(plant, robot, config):
    """A system without the helper's ports."""
    return LeafSystem()
